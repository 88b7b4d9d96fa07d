// The frame's metadata as EXR header attributes; the conventions are derived in exr_metadata.h.
#include "output/exr_metadata.h"

#include <ImfDoubleAttribute.h>
#include <ImfFramesPerSecond.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfRationalAttribute.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfTimeCodeAttribute.h>

#include <cmath>
#include <stdexcept>

#include "pmr/version.h"

namespace pmr {

glm::dmat4 exr_world_to_camera(const Rig& rig, int view) {
  glm::dmat4 flip(1.0);
  flip[2][2] = -1.0;  // F = diag(1, 1, -1, 1): view-space -z (forward) becomes +z
  return flip * rig.view_matrix(view);
}

glm::dmat4 exr_world_to_ndc(const Rig& rig, int view) {
  // S (glm is column-major: s[c][r] is row r of column c)
  glm::dmat4 s(0.0);
  s[0][0] = 0.5;  // x' = x_c / 2 + w_c / 2
  s[3][0] = 0.5;
  s[1][1] = -0.5;  // y' = -y_c / 2 + w_c / 2
  s[3][1] = 0.5;
  s[2][2] = 1.0;  // z' = z_c
  s[3][3] = 1.0;  // w' = w_c
  return s * rig.projection(view) * rig.view_matrix(view);
}

glm::dmat4 quilt_tile_to_ndc(const QuiltLayout& layout, int view) {
  const double columns = layout.columns, rows = layout.rows;
  const double column = view % layout.columns, row_from_top = layout.rows - 1 - view / layout.columns;
  glm::dmat4 q(1.0);
  q[0][0] = 1.0 / columns;
  q[3][0] = column / columns;  // times w: the map stays right after the perspective division
  q[1][1] = 1.0 / rows;
  q[3][1] = row_from_top / rows;
  return q;
}

Imath::M44f to_imath_rows(const glm::dmat4& m) {
  // Imath M[r][c] (row vectors) = A(c, r) (column vectors) = glm m[r][c]: the same 16 numbers in the
  // same order, written out element by element so that the transpose is visible here.
  Imath::M44f out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[r][c] = float(m[r][c]);
  return out;
}

bool exr_time_code(long frame, double fps, int& hours, int& minutes, int& seconds, int& frames) {
  if (!(fps >= 1.0 && fps <= 30.0) || fps != std::floor(fps) || frame < 0) return false;
  const long rate = long(fps), s = frame / rate;
  if (s >= 24L * 3600L) return false;  // SMPTE time codes end at 23:59:59
  hours = int(s / 3600);
  minutes = int(s / 60 % 60);
  seconds = int(s % 60);
  frames = int(frame % rate);
  return true;
}

void add_exr_metadata(Imf::Header& h, const ExrMetadata& meta, ExrImage image, int view) {
  const Rig& rig = meta.rig;
  if (image != ExrImage::Views) view = meta.center_view;
  if (view < 0 || view >= rig.views)
    throw std::invalid_argument("no view " + std::to_string(view) + " in a rig of " + std::to_string(rig.views) +
                                " views");

  // OpenEXR 3.1 has no accessor for `software` (ImfStandardAttributes.h): a plain string attribute
  h.insert("software", Imf::StringAttribute(std::string("pmr ") + program_version()));
  Imf::addFramesPerSecond(h, Imf::guessExactFps(meta.fps));
  int hh = 0, mm = 0, ss = 0, ff = 0;
  if (exr_time_code(meta.frame, meta.fps, hh, mm, ss, ff)) Imf::addTimeCode(h, Imf::TimeCode(hh, mm, ss, ff));
  h.insert("pmrFrame", Imf::IntAttribute(int(meta.frame)));
  h.insert("pmrTime", Imf::DoubleAttribute(meta.time));
  h.insert("pmrFps", Imf::DoubleAttribute(meta.fps));
  if (!meta.sidecar.empty()) h.insert("pmrSidecar", Imf::StringAttribute(meta.sidecar));
  const char* output = image == ExrImage::Views ? "views" : image == ExrImage::Quilt ? "quilt" : "encoded";
  h.insert("pmrOutput", Imf::StringAttribute(output));
  h.insert("pmrView", Imf::IntAttribute(view));
  h.insert("pmrViews", Imf::IntAttribute(rig.views));

  glm::dmat4 ndc = exr_world_to_ndc(rig, view);
  if (image == ExrImage::Quilt) {
    if (meta.quilt.columns < 1 || meta.quilt.rows < 1 || view >= meta.quilt.columns * meta.quilt.rows)
      throw std::invalid_argument("the quilt layout has no tile for view " + std::to_string(view));
    ndc = quilt_tile_to_ndc(meta.quilt, view) * ndc;
  }
  Imf::addWorldToCamera(h, to_imath_rows(exr_world_to_camera(rig, view)));
  Imf::addWorldToNDC(h, to_imath_rows(ndc));

  if (image == ExrImage::Views) {
    // Multi-part multi-view files name each part's view in its `view` attribute and carry no
    // multiView; a views file with a single part is a single-part file showing one of the views, which
    // the OpenEXR multi-view document asks to name in both (docs/OUTPUTS.md).
    const std::string name = h.hasName() ? h.name() : view_part_name(view, rig.views);
    h.setView(name);
    if (rig.views == 1) Imf::addMultiView(h, Imf::StringVector{name});
  }
}

}  // namespace pmr
