// Scene folders: detection, image checks, bounding boxes, on the built-in default scene, copies
// of it with one thing broken, and the real Middlebury dino when shared/ is present.

#include <gtest/gtest.h>

#include "engine/model/error.h"
#include "io/image_io.h"
#include "io/scene_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kDefaultScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

fs::path copy_default_scene(const test::ScratchFolder& folder) {
  const fs::path target = folder / "scene";
  fs::copy(kDefaultScene, target, fs::copy_options::recursive);
  return target;
}

std::string error_of(const fs::path& scene) {
  try {
    io::load_scene(scene);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, LoadsTheDefaultScene) {
  const Scene scene = io::load_scene(kDefaultScene);
  ASSERT_EQ(scene.size(), 4u);
  EXPECT_EQ(scene.camera_format, "middlebury");
  for (const auto& view : scene.views) {
    EXPECT_EQ(view.camera.width(), 80);  // filled in from the PNG headers
    EXPECT_EQ(view.camera.height(), 60);
    // Every camera sees the origin, in the middle of its image.
    const Projection p = view.camera.project(Eigen::Vector3d::Zero());
    EXPECT_GT(p.depth, 0);
    EXPECT_NEAR(p.u, 39.5, 1e-9);
  }
  ASSERT_TRUE(scene.mesh_file.has_value());
  EXPECT_EQ(scene.mesh_file->filename(), "init.off");
  EXPECT_EQ(scene.bounding_box.min, Eigen::Vector3d::Constant(-0.6));
  EXPECT_FALSE(scene.images->is_loaded(0));  // decoded lazily
  EXPECT_EQ(scene.image(2).width(), 80);
  EXPECT_TRUE(scene.images->is_loaded(2));
  EXPECT_FALSE(scene.images->is_loaded(1));
}

TEST(Scene, CameraFileArgumentWorksLikeTheFolder) {
  const Scene scene = io::load_scene(kDefaultScene / "default_par.txt");
  EXPECT_EQ(scene.size(), 4u);
}

TEST(Scene, MissingImageIsNamed) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  fs::remove(scene / "view02.png");
  const std::string message = error_of(scene);
  EXPECT_NE(message.find("default_par.txt: view 2: image 'view02.png' not found"), std::string::npos) << message;
}

TEST(Scene, ImageSizeDisagreeingWithCameraIsNamed) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  // A COLMAP scene whose camera says 80×60 while one image is 81×60.
  test::write_text(scene / "cameras.txt", "1 PINHOLE 80 60 90 90 40 30\n");
  test::write_text(scene / "images.txt",
                   "1 1 0 0 0 0 0 3 1 view00.png\n\n2 1 0 0 0 0 0 3 1 view01.png\n\n");
  fs::remove(scene / "default_par.txt");
  io::write_png(scene / "view01.png", Image(81, 60));
  const std::string message = error_of(scene);
  EXPECT_NE(message.find("view01.png: image is 81x60 pixels but its camera (view 1"), std::string::npos) << message;
}

TEST(Scene, UnreadableImageIsNamedWhenDecoded) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  const std::string png = test::read_text(scene / "view01.png");
  test::write_text(scene / "view01.png", png.substr(0, 200));  // header intact, data truncated
  const Scene loaded = io::load_scene(scene);  // sizes come from headers: fine
  try {
    loaded.image(1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("view01.png"), std::string::npos);
  }
  io::SceneLoadOptions decode;
  decode.decode_images = true;
  EXPECT_THROW(io::load_scene(scene, decode), InputError);
}

TEST(Scene, SeveralCameraFilesAreAnErrorListingThem) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  fs::copy(scene / "default_par.txt", scene / "other_par.txt");
  const std::string message = error_of(scene);
  EXPECT_NE(message.find("default_par.txt, other_par.txt"), std::string::npos) << message;
}

TEST(Scene, FolderWithoutCamerasSaysWhatWasExpected) {
  test::ScratchFolder folder;
  const std::string message = error_of(folder.path());
  EXPECT_NE(message.find("no cameras found"), std::string::npos) << message;
  EXPECT_NE(error_of(folder / "absent").find("scene not found"), std::string::npos);
}

TEST(Scene, BadBoundingBoxFileIsNamed) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  test::write_text(scene / "bbox.txt", "0 0 0\n1 x 1\n");
  const std::string message = error_of(scene);
  EXPECT_NE(message.find("bbox.txt:2: expected a number"), std::string::npos) << message;
}

TEST(Scene, EstimatedBoxIsSeenByEveryCamera) {
  test::ScratchFolder folder;
  const fs::path scene = copy_default_scene(folder);
  fs::remove(scene / "bbox.txt");
  const Scene loaded = io::load_scene(scene);
  ASSERT_FALSE(loaded.bounding_box.is_empty());
  // The cameras look at the origin: the estimate is centred there.
  EXPECT_LT(loaded.bounding_box.centre().norm(), 1e-9);
  for (const auto& view : loaded.views)
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p((corner & 1) ? loaded.bounding_box.max.x() : loaded.bounding_box.min.x(),
                              (corner & 2) ? loaded.bounding_box.max.y() : loaded.bounding_box.min.y(),
                              (corner & 4) ? loaded.bounding_box.max.z() : loaded.bounding_box.min.z());
      const Projection q = view.camera.project(p);
      EXPECT_TRUE(q.depth > 0 && view.camera.in_image(q.u, q.v));
    }
}

TEST(Scene, MiddleburyDinoWithReadmeBox) {
  const fs::path dino = fs::path(MVFLOW_SHARED_DATA) / "dinoSparseRing";
  if (!fs::exists(dino)) GTEST_SKIP() << "shared data not present";
  const Scene scene = io::load_scene(dino);
  ASSERT_EQ(scene.size(), 16u);
  EXPECT_EQ(scene.views[0].camera.width(), 640);
  EXPECT_EQ(scene.views[0].camera.height(), 480);
  EXPECT_NEAR(scene.bounding_box.min.x(), -0.061897, 1e-12);
  EXPECT_NEAR(scene.bounding_box.max.z(), 0.015495, 1e-12);
  // The box centre is in front of every camera and inside every image.
  for (const auto& view : scene.views) {
    const Projection p = view.camera.project(scene.bounding_box.centre());
    EXPECT_GT(p.depth, 0);
    EXPECT_TRUE(view.camera.in_image(p.u, p.v));
  }
}

}  // namespace
}  // namespace mvflow
