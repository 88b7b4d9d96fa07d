#include "reference/reference.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace pmr::ref {

namespace {

constexpr uint32_t kCullBits =
    PMR_CULL_LEFT | PMR_CULL_RIGHT | PMR_CULL_BOTTOM | PMR_CULL_TOP | PMR_CULL_NEAR | PMR_CULL_FAR;

PmrVertex project(const PmrParams& P, double xv, double yv, double zv) {
  PmrVertex out{};
  const double w = -zv;
  const double kk = P.disparity_k / double(P.view_w);
  const double xc = P.ndc_scale_x * xv + P.ndc_offset_x * w;
  const double xfirst = xc - kk * (w - P.focal), xlast = xc + kk * (w - P.focal);
  const double yc = P.ndc_scale_y * yv;
  const double gx = P.guard_ndc_x * w, gy = P.guard_ndc_y * w;
  uint32_t oc = 0;
  if (w < P.near_eff) oc |= PMR_CLIP_NEAR | PMR_CULL_NEAR;
  if (w > P.far) oc |= PMR_CLIP_FAR | PMR_CULL_FAR;
  if (xfirst > gx) oc |= 1u << 2;
  if (xfirst < -gx) oc |= 1u << 3;
  if (xlast > gx) oc |= 1u << 4;
  if (xlast < -gx) oc |= 1u << 5;
  if (yc > gy) oc |= 1u << 6;
  if (yc < -gy) oc |= 1u << 7;
  if (xfirst < -w && xlast < -w) oc |= PMR_CULL_LEFT;
  if (xfirst > w && xlast > w) oc |= PMR_CULL_RIGHT;
  if (yc < -w) oc |= PMR_CULL_BOTTOM;
  if (yc > w) oc |= PMR_CULL_TOP;
  out.pos_view[0] = xv;
  out.pos_view[1] = yv;
  out.pos_view[2] = zv;
  out.outcode = oc;
  if (!(w > 0.0)) return out;
  const double half_w = 0.5 * P.view_w, half_h = 0.5 * P.view_h;
  const double x_center = (xc / w + 1.0) * half_w;
  double x_first = x_center, d = 0.0;
  if (P.views > 1) {
    const double delta = P.disparity_k * (1.0 - P.focal / w);
    x_first = x_center + P.view_anchor * delta;  // at view coordinate 0
    d = delta / P.view_scale;                    // per view coordinate unit
  }
  const double y = (1.0 - yc / w) * half_h;
  auto snap = [](double v) { return int32_t(std::min(std::max(std::floor(v + 0.5), -2.0e9), 2.0e9)); };
  out.x0 = snap(x_first * PMR_X_ONE);
  out.dx = snap(d * PMR_X_ONE);
  out.y = snap(y * PMR_Y_ONE);
  out.z = float(P.far * (w - P.near_eff) / ((P.far - P.near_eff) * w));
  out.inv_w = float(1.0 / w);
  return out;
}

double plane_value(const PmrParams& P, int k, const double* p) {
  const double w = -p[2];
  const double kk = P.disparity_k / double(P.view_w);
  const double xc = P.ndc_scale_x * p[0] + P.ndc_offset_x * w;
  switch (k) {
    case 0:
      return w - P.near_eff;
    case 1:
      return P.far - w;
    case 2:
      return P.guard_ndc_x * w - (xc - kk * (w - P.focal));
    case 3:
      return P.guard_ndc_x * w + (xc - kk * (w - P.focal));
    case 4:
      return P.guard_ndc_x * w - (xc + kk * (w - P.focal));
    case 5:
      return P.guard_ndc_x * w + (xc + kk * (w - P.focal));
    case 6:
      return P.guard_ndc_y * w - P.ndc_scale_y * p[1];
    default:
      return P.guard_ndc_y * w + P.ndc_scale_y * p[1];
  }
}

// Depth of a triangle at raster point (X, Y) (16.16 / 24.8) of a view, given the view's snapped vertex
// positions: the plane anchored at the center (Xr, Yr) of vertex 0's pixel, evaluated exactly as
// cl/common.h's DepthPlane states it (same operations, same order, no contraction) for every sample,
// pixel center or not.
float depth_at(const int64_t* x, const int64_t* y, const ClippedTriangle& c, int64_t X, int64_t Y) {
  const int64_t area = (y[1] - y[0]) * (x[2] - x[0]) - (x[1] - x[0]) * (y[2] - y[0]);
  const double inv = 1.0 / double(area);
  const double dz1 = double(c.v[1].z) - double(c.v[0].z), dz2 = double(c.v[2].z) - double(c.v[0].z);
  const double gx = (dz1 * double(y[0] - y[2]) + dz2 * double(y[1] - y[0])) * double(PMR_X_ONE) * inv;
  const double gy = (dz1 * double(x[2] - x[0]) - dz2 * double(x[1] - x[0])) * double(PMR_Y_ONE) * inv;
  const int64_t pr = x[0] >> PMR_X_FRAC_BITS, qr = y[0] >> PMR_Y_FRAC_BITS;
  const int64_t Xr = pr * PMR_X_ONE + PMR_X_ONE / 2, Yr = qr * PMR_Y_ONE + PMR_Y_ONE / 2;
  const double zr =
      double(c.v[0].z) + gx * (double(Xr - x[0]) / double(PMR_X_ONE)) + gy * (double(Yr - y[0]) / double(PMR_Y_ONE));
  const float zrow = float(zr + gy * (double(Y - Yr) / double(PMR_Y_ONE)));
  return zrow + float(gx) * (float(X - Xr) / float(PMR_X_ONE));
}

struct CV {
  double p[3], b[2];
  int src;
};

}  // namespace

PmrVertex transform_vertex(const PmrParams& P, const float* pos) {
  const double* V = P.view;
  const double px = pos[0], py = pos[1], pz = pos[2];
  return project(P, V[0] * px + V[4] * py + V[8] * pz + V[12], V[1] * px + V[5] * py + V[9] * pz + V[13],
                 V[2] * px + V[6] * py + V[10] * pz + V[14]);
}

std::vector<ClippedTriangle> clip_triangles(const PmrParams& P, const Scene& scene,
                                            const std::vector<PmrVertex>& verts) {
  std::vector<ClippedTriangle> out;
  const double ident[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  for (uint32_t t = 0; t < scene.triangles.size(); ++t) {
    const PmrTriangle& tri = scene.triangles[t];
    const PmrMaterial& mat = scene.materials[tri.material];
    const PmrVertex v[3] = {verts[tri.v[0]], verts[tri.v[1]], verts[tri.v[2]]};
    const uint32_t oc_and = v[0].outcode & v[1].outcode & v[2].outcode;
    const uint32_t oc_or = v[0].outcode | v[1].outcode | v[2].outcode;
    if (oc_and & kCullBits) continue;
    std::vector<CV> poly(3);
    for (int k = 0; k < 3; ++k) {
      poly[k] = CV{{v[k].pos_view[0], v[k].pos_view[1], v[k].pos_view[2]}, {ident[k][0], ident[k][1]}, k};
    }
    for (int plane = 0; plane < 8 && poly.size() >= 3; ++plane) {
      if (!(oc_or & (1u << plane))) continue;
      std::vector<CV> next;
      for (size_t k = 0; k < poly.size(); ++k) {
        const CV& A = poly[k];
        const CV& B = poly[(k + 1) % poly.size()];
        const double fa = plane_value(P, plane, A.p), fb = plane_value(P, plane, B.p);
        if (fa >= 0.0) next.push_back(A);
        if ((fa >= 0.0) != (fb >= 0.0)) {
          // the intersection is computed from the lexicographically smaller end point
          const bool a_first = std::make_tuple(A.p[0], A.p[1], A.p[2]) < std::make_tuple(B.p[0], B.p[1], B.p[2]);
          const CV& F = a_first ? A : B;
          const CV& S = a_first ? B : A;
          const double ff = a_first ? fa : fb, fs = a_first ? fb : fa;
          const double s = ff / (ff - fs);
          CV o;
          for (int c = 0; c < 3; ++c) o.p[c] = F.p[c] + s * (S.p[c] - F.p[c]);
          for (int c = 0; c < 2; ++c) o.b[c] = F.b[c] + s * (S.b[c] - F.b[c]);
          o.src = -1;
          next.push_back(o);
        }
      }
      poly.swap(next);
    }
    if (poly.size() < 3) continue;
    std::vector<PmrVertex> pv(poly.size());
    for (size_t k = 0; k < poly.size(); ++k)
      pv[k] = poly[k].src >= 0 ? v[poly[k].src] : project(P, poly[k].p[0], poly[k].p[1], poly[k].p[2]);
    for (size_t k = 1; k + 1 < poly.size(); ++k) {
      ClippedTriangle c;
      const size_t idx[3] = {0, k, k + 1};
      for (int j = 0; j < 3; ++j) {
        c.v[j] = pv[idx[j]];
        c.bary[j][0] = poly[idx[j]].b[0];
        c.bary[j][1] = poly[idx[j]].b[1];
      }
      c.tri = t;
      c.key = (t << PMR_KEY_SUB_BITS) | uint32_t(k - 1);
      c.double_sided = mat.double_sided != 0;
      c.mask = mat.alpha_mode == PMR_ALPHA_MASK;
      c.transmissive = P.shading == PMR_SHADING_PBR && mat.transmission > 0.0f;
      out.push_back(c);
    }
  }
  return out;
}

namespace {

// Whether view i's bounding box of the MTA holds a sample position, by brute force over the raster's
// rows and columns: with --sampling view (PMR_SAMPLES_CENTER) the samples are the pixel centers plus
// the pattern; a subpixel's samples lie anywhere in its pixel, so every view is kept then.
bool box_holds_sample(const PmrParams& P, const PmrMta& m, int i) {
  if (P.sample_area != PMR_SAMPLES_CENTER) return true;
  int64_t xs[3];
  for (int k = 0; k < 3; ++k) xs[k] = int64_t(m.x0[k]) + int64_t(P.view_coord[i]) * m.dx[k];
  const int64_t xlo = std::min({xs[0], xs[1], xs[2]}), xhi = std::max({xs[0], xs[1], xs[2]});
  const int64_t ylo = std::min({m.y[0], m.y[1], m.y[2]}), yhi = std::max({m.y[0], m.y[1], m.y[2]});
  for (uint32_t s = 0; s < P.samples; ++s) {
    bool row = false, column = false;
    for (int py = 0; py < P.view_h && !row; ++py) {
      const int64_t y = int64_t(py) * PMR_Y_ONE + PMR_Y_ONE / 2 + P.sample_y[s];
      row = y >= ylo && y <= yhi;
    }
    for (int px = 0; px < P.view_w && !column; ++px) {
      const int64_t x = int64_t(px) * PMR_X_ONE + PMR_X_ONE / 2 + P.sample_x[s];
      column = x >= xlo && x <= xhi;
    }
    if (row && column) return true;
  }
  return false;
}

}  // namespace

std::vector<PmrMta> make_mtas(const PmrParams& P, const std::vector<ClippedTriangle>& tris) {
  std::vector<PmrMta> out;
  for (const ClippedTriangle& c : tris) {
    PmrMta m{};
    for (int k = 0; k < 3; ++k) {
      m.x0[k] = c.v[k].x0;
      m.dx[k] = c.v[k].dx;
      m.y[k] = c.v[k].y;
      m.z[k] = c.v[k].z;
      m.inv_w[k] = c.v[k].inv_w;
      m.bary[k][0] = float(c.bary[k][0]);
      m.bary[k][1] = float(c.bary[k][1]);
    }
    m.tri = c.tri;
    m.key = c.key;
    // Orientation by brute force over the views: the runs of positive and negative area.
    for (int sign : {1, -1}) {
      if (sign < 0 && !c.double_sided) break;
      int lo = -1, hi = -1;
      for (int i = 0; i < P.views; ++i) {
        int64_t xs[3];
        for (int k = 0; k < 3; ++k) xs[k] = int64_t(m.x0[k]) + int64_t(P.view_coord[i]) * m.dx[k];
        const int64_t area = int64_t(m.y[1] - m.y[0]) * (xs[2] - xs[0]) - (xs[1] - xs[0]) * int64_t(m.y[2] - m.y[0]);
        if (sign * area > 0) {
          if (lo < 0) lo = i;
          hi = i;
        }
      }
      // setup keeps the views from the first to the last whose box holds a sample
      while (lo >= 0 && lo <= hi && !box_holds_sample(P, m, lo)) ++lo;
      while (lo >= 0 && hi > lo && !box_holds_sample(P, m, hi)) --hi;
      if (lo < 0 || lo > hi) continue;
      PmrMta r = m;
      r.view_lo = lo;
      r.view_hi = hi;
      r.sign = sign;
      r.flags =
          (c.mask ? PMR_MTA_MASK : 0u) | (c.transmissive ? PMR_MTA_TRANSMISSIVE : 0u) | (sign < 0 ? PMR_MTA_BACK : 0u);
      out.push_back(r);
    }
  }
  sort_mtas(out);
  return out;
}

void sort_mtas(std::vector<PmrMta>& mtas) {
  std::sort(mtas.begin(), mtas.end(), [](const PmrMta& a, const PmrMta& b) {
    return std::make_pair(a.key, a.view_lo) < std::make_pair(b.key, b.view_lo);
  });
}

ViewTriangle view_triangle(const ClippedTriangle& c, int64_t v) {
  ViewTriangle t;
  for (int k = 0; k < 3; ++k) {
    t.x[k] = int64_t(c.v[k].x0) + v * c.v[k].dx;
    t.y[k] = c.v[k].y;
  }
  // twice the signed area; > 0 is counter-clockwise in NDC (front) because raster y points down
  const int64_t area = (t.y[1] - t.y[0]) * (t.x[2] - t.x[0]) - (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]);
  t.drawn = area != 0 && (area > 0 || c.double_sided);
  t.sign = area > 0 ? 1 : -1;
  // edge k is opposite vertex k: (1,2), (2,0), (0,1)
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  for (int k = 0; k < 3; ++k) {
    // oriented edge direction; top edge: horizontal going left (y down); left edge: going down
    const int64_t dx = t.sign * (t.x[eb[k]] - t.x[ea[k]]), dy = t.sign * (t.y[eb[k]] - t.y[ea[k]]);
    t.bias[k] = dy > 0 || (dy == 0 && dx < 0) ? 0 : 1;
  }
  return t;
}

bool covers(const ViewTriangle& t, int64_t X, int64_t Y) {
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  for (int k = 0; k < 3; ++k) {
    const int a = ea[k], b = eb[k];
    if (t.sign * ((t.y[b] - t.y[a]) * (X - t.x[a]) - (t.x[b] - t.x[a]) * (Y - t.y[a])) < t.bias[k]) return false;
  }
  return t.drawn;
}

RasterResult rasterize(const PmrParams& P, const std::vector<ClippedTriangle>& tris) {
  const size_t W = size_t(P.view_w), H = size_t(P.view_h), N = size_t(P.views), S = P.samples;
  RasterResult r;
  r.key.assign(W * H * N * S, PMR_NO_KEY);
  r.depth.assign(W * H * N * S, INFINITY);
  r.count.assign(W * H * N * S, 0);
  for (size_t i = 0; i < N; ++i) {
    for (const ClippedTriangle& c : tris) {
      const ViewTriangle t = view_triangle(c, P.view_coord[i]);
      if (!t.drawn) continue;
      for (size_t at = 0; at < W * H * S; ++at) {
        const size_t px = at / S % W, py = at / S / W, sample = at % S;
        const int64_t X = int64_t(px) * PMR_X_ONE + PMR_X_ONE / 2 + P.sample_x[sample],
                      Y = int64_t(py) * PMR_Y_ONE + PMR_Y_ONE / 2 + P.sample_y[sample];
        if (!covers(t, X, Y)) continue;
        const size_t slot = i * H * W * S + at;
        ++r.count[slot];
        const float depth = depth_at(t.x, t.y, c, X, Y);
        if (depth < r.depth[slot] || (depth == r.depth[slot] && c.key < r.key[slot])) {
          r.depth[slot] = depth;
          r.key[slot] = c.key;
        }
      }
    }
  }
  return r;
}

SubpixelResult rasterize_subpixels(const PmrParams& P, const std::vector<ClippedTriangle>& tris,
                                   const std::vector<int>& view_of, int display_w, int display_h) {
  const size_t n = size_t(3) * display_w * display_h, S = P.samples;
  SubpixelResult r;
  r.key.assign(n * S, PMR_NO_KEY);
  r.depth.assign(n * S, INFINITY);
  r.x.resize(n);
  r.y.resize(n);
  for (int i = 0; i < display_h; ++i)
    for (int s = 0; s < 3 * display_w; ++s) {
      const size_t at = size_t(i) * 3 * display_w + size_t(s);
      // floor((s + 1/2) / (3 W_d) * W * 2^16) and floor((i + 1/2) / H_d * H * 2^8), in integers
      r.x[at] = (int64_t(2 * s + 1) * P.view_w * PMR_X_ONE) / (int64_t(6) * display_w);
      r.y[at] = (int64_t(2 * i + 1) * P.view_h * PMR_Y_ONE) / (int64_t(2) * display_h);
      for (const ClippedTriangle& c : tris) {
        const ViewTriangle t = view_triangle(c, P.view_coord[view_of[at]]);
        for (size_t k = 0; k < S; ++k) {
          const int64_t X = r.x[at] + P.sample_x[k], Y = r.y[at] + P.sample_y[k];
          if (!covers(t, X, Y)) continue;
          const float depth = depth_at(t.x, t.y, c, X, Y);
          const size_t slot = at * S + k;
          if (depth < r.depth[slot] || (depth == r.depth[slot] && c.key < r.key[slot])) {
            r.depth[slot] = depth;
            r.key[slot] = c.key;
          }
        }
      }
    }
  return r;
}

RasterResult render(const PmrParams& P, const Scene& scene) {
  std::vector<PmrVertex> verts;
  for (const auto& p : scene.positions) verts.push_back(transform_vertex(P, &p.x));
  return rasterize(P, clip_triangles(P, scene, verts));
}

}  // namespace pmr::ref
