// The `mvflow` Python module (README "Python"): refine, hull, evaluate, mesh files and the
// background worker, over NumPy arrays (vertices N×3 float64, faces M×3 int64) and paths. Every
// call that works releases the GIL; mvflow's errors become mvflow.InputError (a ValueError),
// mvflow.IoError (an OSError) or mvflow.Error (a RuntimeError), carrying the "FILE:LINE: ..."
// message. Refine options are the command line's, named without the dashes
// (max_view_angle=50 is --max-view-angle 50) and checked by the same table.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "engine/worker/worker.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/eval/evaluation.h"
#include "stages/flow/photo_kernel.h"
#include "tools/hull_options.h"
#include "tools/refine_option_table.h"

#ifndef MVFLOW_VERSION
#define MVFLOW_VERSION "unknown"
#endif

namespace py = pybind11;

namespace mvflow::python {
namespace {

namespace fs = std::filesystem;
using Vertices = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Faces = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

std::string shape_of(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d) text += (d ? ", " : "") + std::to_string(array.shape(d));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

//! An IndexedMesh from arrays; InputError naming the argument and the element otherwise.
IndexedMesh indexed_from_arrays(const Vertices& vertices, const Faces& faces) {
  if (vertices.ndim() != 2 || vertices.shape(1) != 3)
    throw InputError("vertices: expected an N×3 array, got shape " + shape_of(vertices));
  if (faces.ndim() != 2 || faces.shape(1) != 3)
    throw InputError("faces: expected an M×3 array of vertex indices, got shape " + shape_of(faces));
  IndexedMesh mesh;
  const auto v = vertices.unchecked<2>();
  for (py::ssize_t i = 0; i < v.shape(0); ++i) mesh.positions.emplace_back(v(i, 0), v(i, 1), v(i, 2));
  const auto f = faces.unchecked<2>();
  for (py::ssize_t i = 0; i < f.shape(0); ++i) {
    std::array<std::uint32_t, 3> triangle{};
    for (int c = 0; c < 3; ++c) {
      if (f(i, c) < 0 || f(i, c) >= v.shape(0))
        throw InputError("faces[" + std::to_string(i) + "]: vertex index " + std::to_string(f(i, c)) +
                         " is out of range (" + std::to_string(v.shape(0)) + " vertices)");
      triangle[c] = static_cast<std::uint32_t>(f(i, c));
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

py::tuple arrays_from_indexed(const IndexedMesh& mesh) {
  Vertices vertices({static_cast<py::ssize_t>(mesh.positions.size()), py::ssize_t{3}});
  auto v = vertices.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) v(static_cast<py::ssize_t>(i), c) = mesh.positions[i][c];
  Faces faces({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
  auto f = faces.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) f(static_cast<py::ssize_t>(i), c) = mesh.triangles[i][c];
  return py::make_tuple(vertices, faces);
}

bool is_path(const py::handle& object) {
  return py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__");
}

//! A mesh argument: a path or a (vertices, faces) pair. Read with the GIL held only for the arrays.
IndexedMesh mesh_argument(const py::handle& object, const char* name) {
  if (is_path(object)) {
    const fs::path file = object.cast<fs::path>();
    py::gil_scoped_release release;
    return io::read_mesh(file);
  }
  if (py::isinstance<py::tuple>(object) || py::isinstance<py::list>(object)) {
    const py::sequence pair = object.cast<py::sequence>();
    if (pair.size() == 2) return indexed_from_arrays(pair[0].cast<Vertices>(), pair[1].cast<Faces>());
  }
  throw InputError(std::string(name) + ": expected a path or a (vertices, faces) pair");
}

//! The command-line arguments for keyword arguments: key_name=value is --key-name VALUE; True and
//! False are on and off; a list or tuple is comma-separated.
std::vector<std::string> flags_of(const py::kwargs& kwargs) {
  std::vector<std::string> args;
  for (const auto& [key, value] : kwargs) {
    std::string flag = "--" + key.cast<std::string>();
    for (char& c : flag)
      if (c == '_') c = '-';
    std::string text;
    if (py::isinstance<py::bool_>(value)) {
      text = value.cast<bool>() ? "on" : "off";
    } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
      for (const auto& item : value.cast<py::sequence>()) {
        if (!text.empty()) text += ',';
        text += py::str(item).cast<std::string>();
      }
    } else {
      text = py::str(value).cast<std::string>();
    }
    args.push_back(flag);
    args.push_back(text);
  }
  return args;
}

//! Parses \p args (in order) with \p app; a usage error becomes InputError naming \p what.
void parse(CLI::App& app, std::vector<std::string> args, const std::string& what) {
  std::reverse(args.begin(), args.end());  // CLI11 takes the vector back to front
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError(what + ": " + e.what());
  }
}

RefineOptions refine_options(const std::string& preset_name, const py::kwargs& kwargs) {
  CLI::App app;
  cli::add_refine_options(app);
  parse(app, flags_of(kwargs), "refine options");
  try {
    return cli::resolve_refine_options(preset_name, app);  // checked: InputError now, not a failed run later
  } catch (const CLI::ParseError& e) {
    throw InputError(std::string("refine options: ") + e.what());
  }
}

std::shared_ptr<spdlog::logger> warnings_logger() {
  static const auto logger = [] {
    auto log = std::make_shared<spdlog::logger>("mvflow-python", std::make_shared<spdlog::sinks::stderr_sink_mt>());
    log->set_pattern("[mvflow %l] %v");
    log->set_level(spdlog::level::warn);
    return log;
  }();
  return logger;
}

py::dict summary_dict(const RefineSummary& summary) {
  py::dict d;
  d["status"] = to_string(summary.status);
  d["message"] = summary.message;
  d["iterations"] = summary.iterations.size();
  d["initial_vertices"] = summary.initial_vertices;
  d["final_vertices"] = summary.final_vertices;
  d["initial_sum_g_per_vertex"] = summary.initial_sum_g_per_vertex;
  d["final_sum_g_per_vertex"] = summary.final_sum_g_per_vertex;
  d["image_noise"] = summary.image_noise;
  d["denoise_sigma"] = summary.denoise_sigma;
  d["settled_tolerance"] = summary.settled_tolerance;
  d["self_intersections"] = summary.self_intersections;
  d["seconds"] = summary.seconds;
  return d;
}

//! The refined mesh's arrays and its summary; quality holds g per vertex.
py::dict result_dict(const RefineSummary& summary, const Mesh& mesh) {
  py::dict d = summary_dict(summary);
  const IndexedMesh indexed = to_indexed(mesh);
  const py::tuple arrays = arrays_from_indexed(indexed);
  d["vertices"] = arrays[0];
  d["faces"] = arrays[1];
  d["quality"] = py::array_t<float>(static_cast<py::ssize_t>(indexed.quality.size()), indexed.quality.data());
  return d;
}

py::dict refine(const fs::path& scene_path, const py::object& mesh, const std::string& preset_name, int threads,
                const py::object& masks, const py::kwargs& kwargs) {
  const RefineOptions options = refine_options(preset_name, kwargs);
  std::optional<IndexedMesh> given;
  if (!mesh.is_none()) given = mesh_argument(mesh, "mesh");
  const std::optional<fs::path> mask_folder =
      masks.is_none() ? std::nullopt : std::optional<fs::path>(masks.cast<fs::path>());  // with the GIL
  RefineResult result;
  {
    py::gil_scoped_release release;
    const Scene scene = io::load_scene(scene_path, {.mask_folder = mask_folder.value_or(fs::path())});
    Mesh initial;
    if (given) {
      initial = build_mesh(*given, "mesh argument");
    } else {
      if (!scene.mesh_file) throw InputError(scene_path, 0, "no mesh given and no init.* in the scene");
      initial = io::load_mesh(*scene.mesh_file);
    }
    RefineControl control;
    control.threads = threads;
    control.logger = warnings_logger();
    result = refine_mesh(scene, initial, options, control);
  }
  if (result.summary.status == RefineStatus::Failed) throw Error(result.summary.message);
  return result_dict(result.summary, result.mesh);
}

//! `mvflow hull`'s carving in-process (the same options, nothing printed, no file); the mesh as arrays.
py::tuple hull(const fs::path& scene_path, int threads, const py::kwargs& kwargs) {
  cli::HullArguments args;
  CLI::App app;
  cli::add_hull_options(app, args);
  parse(app, flags_of(kwargs), "hull options");
  args.scene = scene_path.string();
  args.threads = threads;
  IndexedMesh mesh;
  {
    py::gil_scoped_release release;
    mesh = cli::carve_hull(args, *warnings_logger()).hull.mesh;
  }
  return arrays_from_indexed(mesh);
}

py::dict evaluate(const py::object& mesh, const py::object& truth, std::size_t samples, double accuracy_fraction,
                  double completeness_threshold, std::uint64_t seed) {
  const IndexedMesh surface = mesh_argument(mesh, "mesh");
  const IndexedMesh reference = mesh_argument(truth, "truth");
  EvaluationOptions options;
  options.samples = samples;
  options.accuracy_fraction = accuracy_fraction;
  options.completeness_threshold = completeness_threshold;
  options.seed = seed;
  EvaluationResult result;
  {
    py::gil_scoped_release release;
    result = evaluate_against_truth(surface, reference, options);
  }
  py::dict d;
  d["mean"] = result.symmetric_mean();
  d["rms"] = result.symmetric_rms();
  d["accuracy"] = result.accuracy();
  d["completeness"] = result.completeness();
  d["hausdorff"] = result.hausdorff();
  d["mesh_to_truth_mean"] = result.mesh_to_truth.mean;
  d["truth_to_mesh_mean"] = result.truth_to_mesh.mean;
  d["truth_diagonal"] = result.truth_diagonal;
  d["threshold"] = result.threshold;
  return d;
}

//! The worker for Python: jobs named by paths or arrays; result() takes the outcome (blocking,
//! without the GIL), so a finished job is kept only until its result is read.
class PythonWorker {
 public:
  explicit PythonWorker(int threads) : worker_(options(threads)) {}

  Worker::JobId submit(const fs::path& scene, const py::object& mesh, const std::string& preset_name,
                       const py::object& masks, const py::kwargs& kwargs) {
    JobSpec spec;
    spec.scene = scene;
    if (!masks.is_none()) spec.masks = masks.cast<fs::path>();
    spec.options = refine_options(preset_name, kwargs);
    if (!mesh.is_none()) {
      if (is_path(mesh))
        spec.mesh = mesh.cast<fs::path>();
      else
        spec.mesh_data = std::make_shared<const Mesh>(build_mesh(mesh_argument(mesh, "mesh"), "mesh argument"));
    }
    return worker_.submit(std::move(spec));
  }

  py::dict progress(Worker::JobId id) const {
    const JobProgress p = worker_.progress(id);
    py::dict d;
    d["state"] = to_string(p.state);
    d["stage"] = to_string(p.stage);
    d["iteration"] = p.iteration;
    d["vertices"] = p.vertices;
    d["sum_g_per_vertex"] = p.sum_g_per_vertex;
    return d;
  }

  void cancel(Worker::JobId id) { worker_.cancel(id); }

  py::dict result(Worker::JobId id) {
    JobOutcome outcome;
    {
      py::gil_scoped_release release;
      outcome = worker_.take(id);
    }
    py::dict d = outcome.state == JobState::Succeeded ? result_dict(outcome.summary, outcome.mesh)
                                                      : summary_dict(outcome.summary);
    d["state"] = to_string(outcome.state);
    d["message"] = outcome.message;
    return d;
  }

 private:
  static WorkerOptions options(int threads) {
    WorkerOptions o;
    o.threads = threads;
    o.logger = warnings_logger();
    return o;
  }
  Worker worker_;
};

}  // namespace
}  // namespace mvflow::python

PYBIND11_MODULE(mvflow, m) {
  using namespace mvflow;
  using namespace mvflow::python;
  m.doc() = "mvflow: refines a coarse mesh of an object into a photo-consistent surface, from calibrated photographs";
  m.attr("__version__") = MVFLOW_VERSION;

  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<IoError> io_error(m, "IoError", PyExc_OSError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const IoError& e) {
      PyErr_SetString(io_error.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  m.def("photo_kernel", &photo_kernel_summary, "Which build of the photo kernel runs and why");
  m.def(
      "read_mesh", [](const fs::path& file) { return arrays_from_indexed(mesh_argument(py::cast(file), "file")); },
      py::arg("file"), "(vertices N×3 float64, faces M×3 int64) of a PLY, OBJ, OFF, STL or VRML file");
  m.def(
      "write_mesh",
      [](const fs::path& file, const Vertices& vertices, const Faces& faces) {
        const IndexedMesh mesh = indexed_from_arrays(vertices, faces);
        py::gil_scoped_release release;
        io::write_mesh(file, mesh);
      },
      py::arg("file"), py::arg("vertices"), py::arg("faces"), "Writes a mesh file (format from the extension), atomically");
  m.def("refine", &refine, py::arg("scene"), py::arg("mesh") = py::none(), py::arg("preset") = "default",
        py::arg("threads") = 0, py::arg("masks") = py::none(),
        "Refines the mesh (a path, (vertices, faces), or None for the scene's init.*) against the scene "
        "(a folder or camera file), with the silhouettes of the mask folder `masks` if given. Keyword arguments are `mvflow refine` options without the dashes. Returns a "
        "dict: vertices, faces, quality (g per vertex), status, iterations, ...");
  m.def("hull", &hull, py::arg("scene"), py::arg("threads") = 0,
        "The visual hull of the scene as (vertices, faces); keyword arguments are `mvflow hull` options "
        "without the dashes (resolution=128, exclude_views=[1, 5], threshold=0.19, ...)");
  m.def("evaluate", &evaluate, py::arg("mesh"), py::arg("truth"), py::arg("samples") = 200000,
        py::arg("accuracy_fraction") = 0.9, py::arg("completeness_threshold") = 0.01, py::arg("seed") = 1,
        "Compares a mesh with the ground truth (each a path or (vertices, faces)): mean, accuracy, completeness, ...");

  py::class_<PythonWorker>(m, "Worker", "Background refinement jobs, run one after another on the worker's own thread")
      .def(py::init<int>(), py::arg("threads") = 0)
      .def("submit", &PythonWorker::submit, py::arg("scene"), py::arg("mesh") = py::none(),
           py::arg("preset") = "default", py::arg("masks") = py::none(),
           "Queues a refine job (masks: a mask folder, as for refine) and returns its id at once")
      .def("progress", &PythonWorker::progress, py::arg("job"),
           "dict: state, stage, iteration, vertices, sum_g_per_vertex")
      .def("cancel", &PythonWorker::cancel, py::arg("job"), "Asks the job to stop; returns at once")
      .def("result", &PythonWorker::result, py::arg("job"),
           "Waits for the job (without the GIL), returns its result and forgets the job");
}
