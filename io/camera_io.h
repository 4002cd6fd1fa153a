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
// - PhotoModeler-style records (thesis §2.1, §B.1), one camera per line, see README "Formats".

#include <filesystem>
#include <vector>

#include "engine/camera.h"

namespace mvflow::io {

enum class CameraFormat { Middlebury, Colmap, PhotoModeler };

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

//! PhotoModeler-style text file (README "Formats").
std::vector<View> read_photomodeler(const std::filesystem::path& file);
//! \throw InputError for a camera the format cannot represent (skew, OpenCV distortion).
void write_photomodeler(const std::filesystem::path& file, const std::vector<View>& views);

//! Reads cameras in \p format from \p path (a file, or for COLMAP a folder).
std::vector<View> read_cameras(const std::filesystem::path& path, CameraFormat format);
void write_cameras(const std::filesystem::path& path, const std::vector<View>& views, CameraFormat format);
//! Parses "middlebury", "colmap", "photomodeler". \throw InputError otherwise.
CameraFormat camera_format_from_name(const std::string& name);
const char* camera_format_name(CameraFormat format);

}  // namespace mvflow::io
