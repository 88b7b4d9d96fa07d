// Every model of the shared glTF corpus that the loader supports renders under --shading pbr at a small
// configuration, shows something and warns only about what it does not draw; the Draco one is refused with a clear message. Skipped when ../shared/gltf
// is absent (as in a user's clone).
#include <gtest/gtest.h>

#include "pmr/error.h"
#include "test_util.h"

namespace pmr {
namespace {

TEST(Corpus, EverySupportedModelRenders) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: corpus render test skipped";
  const auto files = test::corpus_files(dir);
  ASSERT_GT(files.size(), 20u);
  size_t rendered = 0;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    if (f.find("glTF-Draco") != std::string::npos) {
      try {
        load_scene(f);
        ADD_FAILURE() << "Draco-compressed file loaded";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("Draco"), std::string::npos) << e.what();
      }
      continue;
    }
    Scene scene = load_scene(f);
    // The only warnings real models may give: a named material extension drawn without its effect or
    // not implemented (KHR_materials_variants: the default materials are drawn) and KHR_xmp (metadata).
    for (const std::string& w : scene.warnings) {
      const bool material = w.find("KHR_materials_") != std::string::npos;
      const bool allowed = (material && w.find("drawn") != std::string::npos) ||
                           (material && w.find("not implemented, ignored: KHR_materials_") != std::string::npos) ||
                           (w.size() > 7 && w.compare(w.size() - 7, 7, "KHR_xmp") == 0 &&
                            w.find("not implemented, ignored: KHR_xmp") != std::string::npos);
      EXPECT_TRUE(allowed) << "unexpected warning: " << w;
    }
    glm::dvec3 lo, hi;
    scene_bounds(scene, lo, hi);
    RigConfig rc;
    rc.views = 6, rc.view_w = 48, rc.view_h = 24;
    Display d;
    d.width = 160, d.height = 90;
    const Rig rig = make_rig(rc, d, lo, hi);
    std::vector<uint16_t> encoded;
    PipelineConfig pc;
    pc.tile_x = pc.tile_y = pc.tile_v = 4;
    pc.shading = Shading::Pbr;
    const test::Rendered out = test::render_with(scene, rig, pc, &d, &encoded);
    size_t covered = 0;
    for (uint32_t k : out.key) covered += k != PMR_NO_KEY;
    // Morph targets are not applied yet (the base shape is drawn, with a warning); a base shape may
    // be flat and seen edge-on (MorphPrimitivesTest), and an empty frame is then the right answer.
    bool morph_ignored = false;
    for (const std::string& w : scene.warnings) morph_ignored |= w.find("morph targets ignored") != std::string::npos;
    if (!morph_ignored) {
      EXPECT_GT(covered, 0u) << "nothing visible";
    }
    ++rendered;
  }
  EXPECT_GT(rendered, 25u);
}

}  // namespace
}  // namespace pmr
