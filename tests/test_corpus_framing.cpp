// The default framing on real models (DESIGN section 2, --framing box): every view of every model of
// the shared glTF corpus keeps the whole object inside it (no covered pixel on a border row or column),
// on lg-portrait's and paper-8k's rigs. The fill fraction (the object's extent over the view's, on the
// side that binds, in the center view) is printed for the box and the sphere. Skipped without the
// corpus.
#include <gtest/gtest.h>

#include <cstdio>

#include "pmr/display_presets.h"
#include "pmr/error.h"
#include "test_util.h"

namespace pmr {
namespace {

// The extent of the vertices projected into the center view, over the view's size, on the side that
// binds (the larger fraction).
double fill_fraction(const Scene& scene, const Rig& rig) {
  const int center = rig.views / 2;
  const glm::dmat4 m = rig.projection(center) * rig.view_matrix(center);
  double x0 = 1, x1 = -1, y0 = 1, y1 = -1;
  for (const glm::vec3& p : scene.positions) {
    const glm::dvec4 c = m * glm::dvec4(glm::dvec3(p), 1.0);
    x0 = std::min(x0, c.x / c.w), x1 = std::max(x1, c.x / c.w), y0 = std::min(y0, c.y / c.w),
    y1 = std::max(y1, c.y / c.w);
  }
  return std::max(x1 - x0, y1 - y0) / 2.0;
}

// Covered pixels on the border rows and columns of every view.
size_t border_coverage(const test::Rendered& out, const Rig& rig) {
  size_t n = 0;
  const size_t plane = size_t(rig.view_w) * size_t(rig.view_h);
  for (int v = 0; v < rig.views; ++v)
    for (int y = 0; y < rig.view_h; ++y)
      for (int x = 0; x < rig.view_w; ++x)
        if (x == 0 || y == 0 || x == rig.view_w - 1 || y == rig.view_h - 1)
          n += out.key[size_t(v) * plane + size_t(y) * size_t(rig.view_w) + size_t(x)] != PMR_NO_KEY;
  return n;
}

TEST(Corpus, TheDefaultFramingKeepsEveryModelInsideEveryView) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: corpus framing test skipped";
  std::printf("%-44s %-11s %8s %8s\n", "model", "preset", "sphere", "box");
  size_t models = 0;
  for (const std::string& f : test::corpus_files(dir)) {
    if (f.find("glTF-Draco") != std::string::npos) continue;
    const Scene scene = load_scene(f);
    glm::dvec3 lo, hi;
    if (!scene_bounds(scene, lo, hi)) continue;
    ++models;
    for (const char* preset : {"lg-portrait", "paper-8k"}) {
      SCOPED_TRACE(f + " " + preset);
      const DisplayPreset& p = find_display_preset(preset);
      RigConfig rc = p.rig;
      rc.views = 9;  // small views, the preset's cone, spacing and aspect
      rc.view_w = p.rig.view_w / 8, rc.view_h = p.rig.view_h / 8;
      rc.framing = Framing::Box;
      const Rig box = make_rig(rc, p.display, lo, hi);
      rc.framing = Framing::Sphere;
      const Rig sphere = make_rig(rc, p.display, lo, hi);
      PipelineConfig pc;
      pc.shading = Shading::Lambert;
      const test::Rendered out = test::render_with(scene, box, pc);
      EXPECT_EQ(border_coverage(out, box), 0u) << "the object reaches a view's border";
      const std::string name = f.substr(dir.size() + 1);
      std::printf("%-44s %-11s %7.0f%% %7.0f%%\n", name.substr(0, 44).c_str(), preset,
                  100.0 * fill_fraction(scene, sphere), 100.0 * fill_fraction(scene, box));
    }
  }
  EXPECT_GT(models, 25u);
}

}  // namespace
}  // namespace pmr
