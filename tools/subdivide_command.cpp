// `mvflow subdivide MESH --scheme S -o OUT`: Loop, modified Loop or modified Butterfly
// subdivision of a mesh, whole or on selected faces (thesis 3.4.1, B.2).

#include <map>

#include "engine/model/error.h"
#include "io/mesh_io.h"
#include "io/text_reader.h"
#include "stages/topology/subdivision.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

struct SubdivideArguments {
  std::string input;
  std::string output;
  std::string scheme;
  std::string faces;
  SubdivisionOptions options;
  bool ascii = false;
};

const std::map<std::string, SubdivisionScheme> kSchemes{
    {"loop", SubdivisionScheme::Loop},
    {"modloop", SubdivisionScheme::ModifiedLoop},
    {"butterfly", SubdivisionScheme::Butterfly}};

//! One flag per face from FILE: face indices separated by whitespace, '#' starts a comment.
std::vector<std::uint8_t> read_face_selection(const std::string& file, std::size_t face_count) {
  std::vector<std::uint8_t> selected(face_count, 0);
  io::TextReader reader(file);
  while (reader.next_content_line('#')) {
    const std::string& line = reader.line();
    for (std::string_view token : io::split_whitespace(std::string_view(line).substr(0, line.find('#')))) {
      const std::string what = "a face index (the mesh has " + std::to_string(face_count) + " faces)";
      const long long index = io::parse_integer(reader, token, what);
      if (static_cast<unsigned long long>(index) >= face_count)
        reader.fail("face index " + std::string(token) + " out of range (the mesh has " +
                    std::to_string(face_count) + " faces, indices 0.." + std::to_string(face_count - 1) + ")");
      selected[static_cast<std::size_t>(index)] = 1;
    }
  }
  return selected;
}

int run_subdivide(const SubdivideArguments& args, spdlog::logger& log) {
  MeshBuildReport report;
  Mesh mesh = io::load_mesh(args.input, &report);
  if (report.rejected_faces > 0) {
    // Skipped faces shift the face ids, so a face list would point at the wrong faces.
    if (!args.faces.empty())
      throw InputError(args.input, 0,
                       std::to_string(report.rejected_faces) +
                           " face(s) would make the mesh non-manifold; fix the mesh before selecting faces with --faces");
    log.warn("{}: {} face(s) skipped as non-manifold", args.input, report.rejected_faces);
  }
  if (!mesh.colors.empty() || !mesh.quality.empty() || !mesh.texcoords.empty())
    log.warn("{}: colours, quality and texture coordinates are not carried over by subdivision", args.input);

  std::vector<std::uint8_t> selected;
  if (!args.faces.empty()) selected = read_face_selection(args.faces, mesh.n_faces());
  SubdivisionOptions options = args.options;
  options.scheme = kSchemes.at(args.scheme);

  Mesh result;
  result.topology = subdivide(mesh.topology, options, args.faces.empty() ? nullptr : &selected);
  io::MeshWriteOptions write_options;
  write_options.binary = !args.ascii;
  io::write_mesh(args.output, to_indexed(result), write_options);
  log.info("wrote {} ({} vertices, {} triangles; input {} vertices, {} triangles)", args.output, result.n_vertices(),
           result.n_faces(), mesh.n_vertices(), mesh.n_faces());
  return kOk;
}

}  // namespace

void add_subdivide_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<SubdivideArguments>();
  CLI::App* command = app.add_subcommand(
      "subdivide",
      "Subdivide a triangle mesh (Loop, modified Loop with sharp edges, or modified Butterfly), whole or on "
      "selected faces. Vertex colours, quality and texture coordinates of the input are dropped.");
  command->add_option("mesh", args->input, "Input mesh (.ply .obj .off .stl .wrl)")->required();
  command->add_option("-o,--output", args->output, "Output mesh; format from the extension, written atomically")
      ->required();
  command
      ->add_option("--scheme", args->scheme,
                   "loop (approximating, Loop 1987), modloop (Loop keeping sharp edges and corners, Hoppe et al. "
                   "1994) or butterfly (interpolating, Zorin et al. 1996)")
      ->required()
      ->check(CLI::IsMember({"loop", "modloop", "butterfly"}));
  command->add_option("--iterations", args->options.iterations, "Subdivision steps; each quadruples the face count")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      ->add_option("--sharp-angle", args->options.sharp_angle_degrees,
                   "modloop: edges whose face normals differ by more than this many degrees stay sharp")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  command->add_option("--faces", args->faces,
                      "Subdivide only these faces: a text file of 0-based face indices separated by whitespace, "
                      "'#' starts a comment; neighbouring faces are split just enough to keep the mesh conforming");
  command->add_flag("--ascii", args->ascii, "Write PLY/STL as ASCII instead of binary");
  command->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_subdivide(*args, log); }; });
}

}  // namespace mvflow::cli
