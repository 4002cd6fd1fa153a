#include "perf/bench_scene.h"

#include <charconv>
#include <chrono>
#include <memory>
#include <optional>
#include <string_view>

#include "engine/model/error.h"
#include "stages/topology/vertex_order.h"

namespace mvflow::perf {

std::string SceneSpec::label() const {
  const std::string count = vertices % 1000 == 0 ? std::to_string(vertices / 1000) + "k" : std::to_string(vertices);
  return count + "/" + std::to_string(views) + "/" + std::to_string(width) + "x" + std::to_string(height);
}

namespace {

// A whole decimal number, or nothing.
std::optional<long> whole_number(std::string_view text) {
  long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace

SceneSpec SceneSpec::parse(const std::string& text) {
  const auto fail = [&] {
    return InputError("scene size '" + text + "': expected VERTICES/VIEWS/WIDTHxHEIGHT, e.g. 10k/16/640x480");
  };
  const auto first = text.find('/'), second = text.find('/', first + 1);
  if (first == std::string::npos || second == std::string::npos) throw fail();
  std::string_view count(text.data(), first);
  const bool thousands = !count.empty() && count.back() == 'k';
  if (thousands) count.remove_suffix(1);
  const std::string_view size(text.data() + second + 1, text.size() - second - 1);
  const auto x = size.find('x');
  const auto vertices = whole_number(count), views = whole_number(std::string_view(text).substr(first + 1, second - first - 1));
  const auto width = x == std::string_view::npos ? std::nullopt : whole_number(size.substr(0, x));
  const auto height = x == std::string_view::npos ? std::nullopt : whole_number(size.substr(x + 1));
  if (!vertices || !views || !width || !height) throw fail();
  SceneSpec spec;
  spec.vertices = static_cast<std::size_t>(*vertices) * (thousands ? 1000 : 1);
  spec.views = static_cast<int>(*views);
  spec.width = static_cast<int>(*width);
  spec.height = static_cast<int>(*height);
  if (spec.vertices < 20 || spec.views < 2 || spec.width < 8 || spec.height < 8) throw fail();
  return spec;
}

BenchScene make_bench_scene(const SceneSpec& spec) {
  const auto start = std::chrono::steady_clock::now();
  BuiltinShapeOptions shape;
  shape.amplitude = spec.amplitude;
  shape.level = 1;
  while (shape.level < 7 && 10.0 * (1 << (2 * shape.level)) + 2 < 1.6 * static_cast<double>(spec.vertices)) ++shape.level;
  SynthOptions options;
  options.rig.views = spec.views;
  options.rig.width = spec.width;
  options.rig.height = spec.height;
  options.render.supersample = spec.supersample;
  options.init.vertices = static_cast<int>(spec.vertices);
  options.init.amount = spec.init_offset;
  BenchScene result;
  result.spec = spec;
  SynthScene synth = make_synth_scene(make_builtin_object("bumpy-sphere", shape), nullptr, options);
  result.scene = in_memory_scene(std::move(synth.views), std::move(synth.images), synth.bounding_box);
  result.initial = build_mesh(synth.initial, "initial");
  // In the order every refinement puts its mesh after the split/collapse: the fixed-topology
  // runs time the iterations of a real run.
  order_vertices_by_locality(result.initial.topology);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace mvflow::perf
