// The frame's metadata in the EXR headers (docs/OUTPUTS.md): OpenEXR's standard attributes (software,
// framesPerSecond, timeCode, view, multiView, worldToCamera, worldToNDC) and pmr's own (pmrFrame,
// pmrTime, pmrFps, pmrSidecar, pmrOutput, pmrView, pmrViews), so that an image separated from its
// sidecar still says what it is. The EXR writers (exr_output.cpp) call add_exr_metadata on each header.
//
// Matrix conventions. The rig (pmr/rig.h) follows glTF / OpenGL: view space is right-handed and looks
// down -z, matrices act on column vectors (p' = M p), clip = P_i V_i p and NDC = clip.xyz / clip.w in
// [-1, 1] with +y up. OpenEXR (ImfStandardAttributes.h, the RenderMan conventions) wants:
//  - worldToCamera: world -> a LEFT-handed camera space, +x right, +y up, +z the viewing direction
//    (points in front of the camera have z > 0): C_i = F V_i with F = diag(1, 1, -1, 1), i.e. the
//    view-space z negated (one axis flipped turns the right-handed space left-handed).
//  - worldToNDC: world -> NDC with (0, 0) the top-left and (1, 1) the bottom-right corner of the
//    display window: x = (x_ndc + 1) / 2, y = (1 - y_ndc) / 2. Written on the homogeneous clip
//    coordinates so that the perspective division still happens last: N_i = S P_i V_i with
//        S = | 1/2    0   0  1/2 |      x' = (x_c + w_c) / 2,  y' = (w_c - y_c) / 2,
//            |   0 -1/2   0  1/2 |      z' = z_c,  w' = w_c;
//            |   0    0   1    0 |      so x' / w' = (x_ndc + 1) / 2, y' / w' = (1 - y_ndc) / 2 and
//            |   0    0   0    1 |      z' / w' = OpenGL's NDC depth in [-1, 1] (near to far).
//    Imath's `V3f p * M44f` divides by w, so `world * worldToNDC` gives the NDC point directly; the
//    pixel is (x * width, y * height) in the image's (0, 0)-(width, height) continuous raster.
//  - Imath matrices act on ROW vectors (p' = p M, translation in the last row): the header holds the
//    transposes, M[r][c] = A(c, r) for the column-vector matrix A above.
// The per-view matrices are Rig::view_matrix(i) and Rig::projection(i): exactly those of the sidecar.
#pragma once
#include <ImfHeader.h>
#include <ImathMatrix.h>

#include <glm/glm.hpp>

#include "pmr/output.h"

namespace pmr {

// world -> OpenEXR camera space (left-handed, +z forward) of view i, column-vector form: F V_i.
glm::dmat4 exr_world_to_camera(const Rig& rig, int view);
// world -> OpenEXR NDC of view i's own raster, column-vector form, homogeneous: S P_i V_i.
glm::dmat4 exr_world_to_ndc(const Rig& rig, int view);
// The affine map from a tile's NDC to the quilt's NDC for view `view` (view 0 in the bottom-left tile,
// then left to right and upward): x_q = (column + x) / columns, y_q = (rows - 1 - row + y) / rows.
glm::dmat4 quilt_tile_to_ndc(const QuiltLayout& layout, int view);
// A column-vector matrix as Imath's row-vector matrix (the transpose), rounded to float.
Imath::M44f to_imath_rows(const glm::dmat4& m);

// The frame rate as OpenEXR's exact rational (Imf::guessExactFps: 29.97 -> 30000/1001, 24 -> 24/1).
// A SMPTE time code (non-drop) for frame f when fps is a whole number from 1 to 30 and the frame lies
// within the first 24 hours; false otherwise (no timeCode attribute is then written).
bool exr_time_code(long frame, double fps, int& hours, int& minutes, int& seconds, int& frames);

// Adds the frame's attributes to the header of an image of kind `image`. `view` is the view the header
// describes: the part's view for ExrImage::Views, ignored (meta.center_view) for the encoded image and
// the quilt. The quilt's worldToNDC lands in the center view's tile. Throws std::invalid_argument when
// the view is out of range (the writers turn it into pmr::Error naming the file). Nothing depends on the time of day: a frame rendered twice gives identical headers.
void add_exr_metadata(Imf::Header& header, const ExrMetadata& meta, ExrImage image, int view);

}  // namespace pmr
