#include "pmr/quilt.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "pmr/error.h"

namespace pmr {

namespace {

bool fits(const QuiltLayout& l, int view_w, int view_h) {
  return int64_t(l.columns) * view_w <= kMaxQuiltSide && int64_t(l.rows) * view_h <= kMaxQuiltSide;
}

// |log(quilt aspect)|: 0 for a square quilt.
double squareness(const QuiltLayout& l, int view_w, int view_h) {
  return std::abs(std::log(double(l.columns) * view_w / (double(l.rows) * view_h)));
}

std::string size_text(const QuiltLayout& l, int view_w, int view_h) {
  return std::to_string(l.columns) + "x" + std::to_string(l.rows) + " (" + std::to_string(int64_t(l.columns) * view_w) +
         "x" + std::to_string(int64_t(l.rows) * view_h) + " px)";
}

}  // namespace

QuiltLayout choose_quilt_layout(int views, int view_w, int view_h) {
  if (views < 1 || view_w < 1 || view_h < 1) throw Error("quilt: invalid view count or size");
  QuiltLayout best;
  double best_score = std::numeric_limits<double>::infinity();
  // Exact factorizations first: no empty tile. Within 2:1 of square they win.
  for (int c = 1; c <= views; ++c) {
    if (views % c) continue;
    const QuiltLayout l{c, views / c};
    const double s = squareness(l, view_w, view_h);
    if (s < best_score - 1e-12 || (std::abs(s - best_score) <= 1e-12 && l.columns > best.columns))
      best = l, best_score = s;
  }
  if (best_score > std::log(2.0)) {
    // e.g. a prime view count: the most square layout with the fewest empty tiles (a square costs
    // at most a row of them)
    double score = std::numeric_limits<double>::infinity();
    for (int c = 1; c <= views; ++c) {
      const QuiltLayout l{c, (views + c - 1) / c};
      const double s = squareness(l, view_w, view_h) + 0.05 * (int64_t(l.columns) * l.rows - views);
      if (s < score) best = l, score = s;
    }
  }
  if (!fits(best, view_w, view_h))
    throw Error("a quilt of " + std::to_string(views) + " views of " + std::to_string(view_w) + "x" +
                std::to_string(view_h) + " would be " + size_text(best, view_w, view_h) + ", over " +
                std::to_string(kMaxQuiltSide) + " px on a side: use a smaller --view-size or fewer --views");
  return best;
}

QuiltLayout parse_quilt_layout(const std::string& text, int views, int view_w, int view_h) {
  int c = 0, r = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &c, &r, &tail) != 2 || c < 1 || r < 1 || c > 4096 || r > 4096)
    throw Error("invalid --quilt '" + text + "': expected COLUMNSxROWS, e.g. 8x6");
  const QuiltLayout l{c, r};
  if (int64_t(c) * r < views)
    throw Error("invalid --quilt '" + text + "': " + std::to_string(c * r) + " tiles for " + std::to_string(views) +
                " views");
  if (!fits(l, view_w, view_h)) {
    std::string hint;
    try {
      hint = "; " + size_text(choose_quilt_layout(views, view_w, view_h), view_w, view_h) + " fits";
    } catch (const Error&) {
      hint = "; use a smaller --view-size";
    }
    throw Error("invalid --quilt '" + text + "': the quilt would be " + size_text(l, view_w, view_h) + ", over " +
                std::to_string(kMaxQuiltSide) + " px on a side" + hint);
  }
  return l;
}

std::string quilt_stem(const std::string& stem, const QuiltLayout& layout, double aspect) {
  if (!(aspect > 0.0) || !std::isfinite(aspect)) throw Error("quilt: invalid view aspect");
  char a[64];
  std::snprintf(a, sizeof a, "%.4f", aspect);
  std::string s = a;
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return stem + "_qs" + std::to_string(layout.columns) + "x" + std::to_string(layout.rows) + "a" + s;
}

void assemble_quilt(const QuiltLayout& l, int views, int view_w, int view_h, const uint16_t* volume, const float* depth,
                    std::vector<uint16_t>& quilt, std::vector<float>* quilt_depth) {
  const size_t qw = size_t(l.columns) * size_t(view_w), qh = size_t(l.rows) * size_t(view_h);
  quilt.assign(qw * qh * 4, 0);
  if (depth && quilt_depth) quilt_depth->assign(qw * qh, std::numeric_limits<float>::infinity());
  for (int v = 0; v < views && v < l.columns * l.rows; ++v) {
    // view 0 bottom-left, left to right, then upward; the image's row 0 is its top
    const size_t x0 = size_t(v % l.columns) * size_t(view_w);
    const size_t y0 = size_t(l.rows - 1 - v / l.columns) * size_t(view_h);
    for (size_t y = 0; y < size_t(view_h); ++y) {
      const size_t src = (size_t(v) * size_t(view_h) + y) * size_t(view_w);
      const size_t dst = (y0 + y) * qw + x0;
      std::memcpy(&quilt[dst * 4], volume + src * 4, size_t(view_w) * 4 * sizeof(uint16_t));
      if (depth && quilt_depth) std::memcpy(&(*quilt_depth)[dst], depth + src, size_t(view_w) * sizeof(float));
    }
  }
}

}  // namespace pmr
