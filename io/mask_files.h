#pragma once
// Silhouette mask files: one image per view in a folder, matched to the view's photograph by
// file-name stem (dinoSR0001.png ↔ masks/dinoSR0001.png, .pgm, .jpg, ...). Any image read_image
// reads (io/image_io.h); a pixel whose largest channel is non-zero is object (stages/flow/silhouette.h turns the
// image into a mask).

#include <filesystem>
#include <memory>
#include <string>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "engine/model/scene.h"

namespace mvflow::io {

//! The name a mask file of \p view is written under: the stem of view.image_name with .png (what
//! find_mask_file finds; `hull --save-masks` and `synth --masks` write it).
std::filesystem::path mask_file_name(const View& view);

//! The mask file of \p view (the \p index-th view of its scene) in \p folder: the one file whose
//! stem is the stem of view.image_name and whose extension is an image format (png, pgm, ppm,
//! pbm, bmp, jpg, jpeg, tif, tiff; any case).
//! \throw IoError when \p folder is not a folder; InputError naming the expected file when
//!        there is none, or listing the candidates when there are several.
std::filesystem::path find_mask_file(const std::filesystem::path& folder, const View& view, std::size_t index);

//! Reads a mask image and checks that it has the size of \p view's camera.
//! \throw as io::read_image; InputError naming the file, both sizes and the view otherwise.
Image read_mask_image(const std::filesystem::path& file, const View& view, std::size_t index);

//! The masks of every view of \p scene in \p folder, for Scene::masks: each file is found now (so a
//! missing or ambiguous one stops the job before any work) and decoded on first use, its size
//! checked against its camera's.
//! \throw as find_mask_file.
std::shared_ptr<ImageStore> mask_store(const std::filesystem::path& folder, const Scene& scene);

}  // namespace mvflow::io
