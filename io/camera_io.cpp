// Dispatch between the camera formats; the formats themselves live in middlebury.cpp, colmap.cpp,
// colmap_binary.cpp and photomodeler.cpp.

#include "io/camera_io.h"

#include "engine/model/error.h"

namespace mvflow::io {

std::vector<View> read_cameras(const std::filesystem::path& path, CameraFormat format) {
  switch (format) {
    case CameraFormat::Middlebury:
      return read_middlebury(path);
    case CameraFormat::Colmap:
      return read_colmap(path);
    case CameraFormat::ColmapBinary:
      return read_colmap_binary(path);
    case CameraFormat::PhotoModeler:
      return read_photomodeler(path);
  }
  MVFLOW_CHECK(false, "read_cameras: unknown CameraFormat");
  return {};
}

void write_cameras(const std::filesystem::path& path, const std::vector<View>& views, CameraFormat format) {
  switch (format) {
    case CameraFormat::Middlebury:
      return write_middlebury(path, views);
    case CameraFormat::Colmap:
      return write_colmap(path, views);
    case CameraFormat::ColmapBinary:
      return write_colmap_binary(path, views);
    case CameraFormat::PhotoModeler:
      return write_photomodeler(path, views);
  }
  MVFLOW_CHECK(false, "write_cameras: unknown CameraFormat");
}

CameraFormat camera_format_from_name(const std::string& name) {
  for (CameraFormat format :
       {CameraFormat::Middlebury, CameraFormat::Colmap, CameraFormat::ColmapBinary, CameraFormat::PhotoModeler})
    if (name == camera_format_name(format)) return format;
  throw InputError("unknown camera format '" + name +
                   "' (expected middlebury, colmap, colmap-bin or photomodeler)");
}

const char* camera_format_name(CameraFormat format) {
  switch (format) {
    case CameraFormat::Middlebury:
      return "middlebury";
    case CameraFormat::Colmap:
      return "colmap";
    case CameraFormat::ColmapBinary:
      return "colmap-bin";
    case CameraFormat::PhotoModeler:
      return "photomodeler";
  }
  return "unknown";
}

}  // namespace mvflow::io
