// Writes the fuzz targets' seed corpora: `make_seeds DATA OUT` reads the test scene in
// DATA/scenes/default (tests/data) and writes it, plus a small textured and coloured mesh and
// three cameras of every distortion model, through mvflow's own writers in every format, one folder
// per target in OUT (tools/fuzz.sh). Seeds of the two-file targets start with their selector byte.

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "engine/model/error.h"
#include "io/camera_io.h"
#include "io/mesh_io.h"
#include "tests/fuzz/sample_views.h"

namespace fs = std::filesystem;
using namespace mvflow;

namespace {

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << bytes;
  if (!out) throw IoError(file, "cannot write the seed");
}

// Six triangles over five vertices with per-vertex colours and quality, texture coordinates per corner.
IndexedMesh small_mesh() {
  IndexedMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}};
  mesh.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0.5f, 0.5f, 0.5f}};
  mesh.quality = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f};
  for (std::size_t corner = 0; corner < 3 * mesh.triangles.size(); ++corner)
    mesh.texcoords.emplace_back(0.1f * static_cast<float>(corner % 7), 0.05f * static_cast<float>(corner));
  mesh.texture_file = "texture.png";
  return mesh;
}

void write_meshes(const fs::path& out, const std::string& stem, const IndexedMesh& mesh) {
  io::MeshWriteOptions ascii;
  ascii.binary = false;
  io::write_mesh(out / "ply" / (stem + "-binary.ply"), mesh);
  io::write_mesh(out / "ply" / (stem + "-ascii.ply"), mesh, ascii);
  io::write_mesh(out / "obj" / (stem + ".obj"), mesh);
  io::write_mesh(out / "off" / (stem + ".off"), mesh);
  io::write_mesh(out / "stl" / (stem + "-binary.stl"), mesh);
  io::write_mesh(out / "stl" / (stem + "-ascii.stl"), mesh, ascii);
  io::write_mesh(out / "vrml" / (stem + ".wrl"), mesh);
}

// The two files of a COLMAP model as seeds of one target: selector byte 0 cameras, 1 images.
void write_model_seeds(const fs::path& model, const fs::path& corpus, const std::string& extension) {
  write_bytes(corpus / ("cameras" + extension), std::string(1, '\0') + read_bytes(model / ("cameras" + extension)));
  write_bytes(corpus / ("images" + extension), std::string(1, '\1') + read_bytes(model / ("images" + extension)));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_seeds DATA OUT (DATA: tests/data)\n";
    return 2;
  }
  const fs::path scene = fs::path(argv[1]) / "scenes" / "default";
  const fs::path out = argv[2];
  try {
    fs::remove_all(out);
    for (const char* target : {"ply", "obj", "off", "stl", "vrml", "middlebury", "photomodeler", "models"})
      fs::create_directories(out / target);
    // Meshes: the test scene's initial mesh and the small attributed one, in every format.
    write_meshes(out, "scene", io::read_mesh(scene / "init.off"));
    write_meshes(out, "small", small_mesh());

    // Cameras: the test scene's Middlebury file, and the sample views in every format.
    const auto views = fuzz::sample_views();
    write_bytes(out / "middlebury" / "scene_par.txt", read_bytes(scene / "default_par.txt"));
    // Middlebury and PhotoModeler-style files hold no COLMAP-style distortion: the first view only.
    io::write_middlebury(out / "middlebury" / "sample_par.txt", {views.front()});
    io::write_photomodeler(out / "photomodeler" / "sample_pm.txt", {views.front()});
    io::write_colmap(out / "models" / "text", views);
    write_model_seeds(out / "models" / "text", out / "colmap_text", ".txt");
    io::write_colmap_binary(out / "models" / "binary", views);
    write_model_seeds(out / "models" / "binary", out / "colmap_binary", ".bin");
    fs::remove_all(out / "models");

    // Bounding boxes: the test scene's bbox.txt and a Middlebury README's box lines.
    write_bytes(out / "bbox" / "bbox.txt", std::string(1, '\0') + read_bytes(scene / "bbox.txt"));
    write_bytes(out / "bbox" / "README.txt",
                std::string(1, '\1') + "The object lies within this bounding box:\n\n"
                                       "(-0.07 -0.02 -0.06)\n( 0.02  0.07  0.06)\n");

    // Masks: a small two-tone image in each extension the target picks (its first byte's index).
    cv::Mat mask(6, 8, CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(2, 1, 4, 4)).setTo(255);
    const char* extensions[] = {".png", ".jpg", ".pgm", ".ppm", ".bmp", ".tif"};
    for (int i = 0; i < 6; ++i) {
      std::vector<unsigned char> bytes;
      cv::Mat image = i == 3 ? cv::Mat() : mask;
      if (i == 3) cv::cvtColor(mask, image, cv::COLOR_GRAY2BGR);
      if (!cv::imencode(extensions[i], image, bytes)) throw IoError(extensions[i], "cannot encode the seed");
      write_bytes(out / "mask" / (std::string("mask") + extensions[i]),
                  std::string(1, static_cast<char>(i)) + std::string(bytes.begin(), bytes.end()));
    }
  } catch (const Error& error) {
    std::cerr << "make_seeds: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
