#pragma once
// Camera files. Every reader returns views in file order (COLMAP: by IMAGE_ID) with pixel
// coordinates converted to mvflow's convention (SPEC §2: pixel (0,0) is the centre of the
// top-left pixel); every writer converts back. Image sizes: Middlebury files carry none, so the reader leaves width/height 0
// unless told them (the scene loader fills them from the images).
//
// - Middlebury `*_par.txt`: first line the count, then per line
//   `name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3`.
// - COLMAP text model: `cameras.txt` + `images.txt` (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL,
//   RADIAL, OPENCV; quaternion world-to-camera; COLMAP's pixel centre is (0.5, 0.5)).
// - COLMAP binary model: `cameras.bin` + `images.bin`, the same content in COLMAP's little-endian
//   layout (COLMAP's default output).
// - PhotoModeler-style records (thesis §2.1, §B.1), one camera per line, see README "Formats".

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "engine/model/camera.h"

namespace mvflow::io {

//! Colmap is the text model, ColmapBinary the binary one.
enum class CameraFormat { Middlebury, Colmap, ColmapBinary, PhotoModeler };

//! Middlebury: a file `*_par.txt`. Views get width = height = 0 when \p width, \p height are 0.
std::vector<View> read_middlebury(const std::filesystem::path& file, int width = 0, int height = 0);
void write_middlebury(const std::filesystem::path& file, const std::vector<View>& views);

//! COLMAP: \p folder holds cameras.txt and images.txt (directly or in sparse/ or sparse/0/).
//! Views are sorted by IMAGE_ID (COLMAP writes images.txt in no guaranteed order).
std::vector<View> read_colmap(const std::filesystem::path& folder);
//! Writes cameras.txt and images.txt into \p folder (one COLMAP camera per view; PINHOLE,
//! SIMPLE_RADIAL, RADIAL or OPENCV chosen from the view's distortion). \throw InputError for a
//! camera COLMAP cannot represent (skew, the thesis's inverse radial model).
void write_colmap(const std::filesystem::path& folder, const std::vector<View>& views);

//! COLMAP binary model: \p folder holds cameras.bin and images.bin (directly or in sparse/ or
//! sparse/0/), in COLMAP's layout, little-endian whatever the host:
//! - cameras.bin: uint64 count, then per camera uint32 CAMERA_ID, int32 model id (0 SIMPLE_PINHOLE,
//!   1 PINHOLE, 2 SIMPLE_RADIAL, 3 RADIAL, 4 OPENCV; COLMAP's other ids are refused by name),
//!   uint64 WIDTH, uint64 HEIGHT, the model's PARAMS as doubles;
//! - images.bin: uint64 count, then per image uint32 IMAGE_ID, double QW QX QY QZ TX TY TZ,
//!   uint32 CAMERA_ID, NAME ending in a NUL byte, uint64 point count, then per point double X, Y
//!   and int64 POINT3D_ID (skipped).
//! points3D.bin is not read (nor is points3D.txt by read_colmap). The models, conventions and
//! checks are read_colmap's, so a binary and a text model with the same numbers give identical
//! views, sorted by IMAGE_ID.
//! \throw InputError "FILE: byte N: expected ..." for a truncated or malformed file (counts that
//! cannot fit in the rest of the file are refused before anything is allocated; trailing bytes are
//! an error); IoError when no folder holds the two files.
std::vector<View> read_colmap_binary(const std::filesystem::path& folder);
//! Writes cameras.bin, images.bin and an empty points3D.bin (count 0) into \p folder, created if
//! needed; the models are write_colmap's. \throw InputError for a camera COLMAP cannot represent,
//! or an image name that is empty or holds a NUL byte; then no file is touched.
void write_colmap_binary(const std::filesystem::path& folder, const std::vector<View>& views);

//! Where a folder's COLMAP model is, and whether it is text or binary.
struct ColmapModel {
  std::filesystem::path folder;  //!< the folder holding the model's files
  CameraFormat format = CameraFormat::Colmap;
};
//! The COLMAP model of \p folder: the first of \p folder, sparse/ and sparse/0/ that holds
//! cameras.bin + images.bin or cameras.txt + images.txt. A folder holding both models gives the
//! binary one, as COLMAP's own reader does. nullopt when there is none.
std::optional<ColmapModel> find_colmap_model(const std::filesystem::path& folder);

//! PhotoModeler-style text file (README "Formats").
std::vector<View> read_photomodeler(const std::filesystem::path& file);
//! \throw InputError for a camera the format cannot represent (skew, OpenCV distortion).
void write_photomodeler(const std::filesystem::path& file, const std::vector<View>& views);

//! True for the COLMAP models, whose camera path is a folder.
inline bool is_colmap(CameraFormat format) {
  return format == CameraFormat::Colmap || format == CameraFormat::ColmapBinary;
}

//! Reads cameras in \p format from \p path (a file, or for COLMAP a folder).
std::vector<View> read_cameras(const std::filesystem::path& path, CameraFormat format);
void write_cameras(const std::filesystem::path& path, const std::vector<View>& views, CameraFormat format);
//! Parses "middlebury", "colmap", "colmap-bin", "photomodeler". \throw InputError otherwise.
CameraFormat camera_format_from_name(const std::string& name);
const char* camera_format_name(CameraFormat format);

}  // namespace mvflow::io
