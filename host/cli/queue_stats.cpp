#include "cli/queue_stats.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace pmr {

namespace {

// Counts in buckets with upper bounds `edges` (the last bucket open): "1", "2", "3-4", ..., "65+".
struct Histogram {
  std::vector<uint64_t> edges, counts;
  uint64_t total = 0, sum = 0;
  explicit Histogram(std::vector<uint64_t> e) : edges(std::move(e)), counts(edges.size() + 1, 0) {}
  void add(uint64_t v) {
    size_t b = 0;
    while (b < edges.size() && v > edges[b]) ++b;
    ++counts[b], ++total, sum += v;
  }
  void print(const char* what) const {
    std::printf("#   %s (mean %.2f):", what, total ? double(sum) / double(total) : 0.0);
    for (size_t b = 0; b < counts.size(); ++b) {
      const uint64_t lo = b == 0 ? 0 : edges[b - 1] + 1;
      const std::string label = b == edges.size() ? std::to_string(lo) + "+"
                                : lo == edges[b]  ? std::to_string(lo)
                                                  : std::to_string(lo) + "-" + std::to_string(edges[b]);
      std::printf(" %s: %.1f%%", label.c_str(), total ? 100.0 * double(counts[b]) / double(total) : 0.0);
    }
    std::printf("\n");
  }
};

// Pixel centers whose x lies in [lo, hi] (16.16), clamped to the view.
int64_t centers_in(int64_t lo, int64_t hi, int64_t one, int64_t size) {
  const int64_t half = one / 2;
  const int64_t a =
      std::max<int64_t>(0, (lo - half + one - 1) >= 0 ? (lo - half + one - 1) / one : -((half - lo) / one));
  const int64_t b = std::min<int64_t>(size - 1, (hi - half) >= 0 ? (hi - half) / one : -1);
  return std::max<int64_t>(0, b - a + 1);
}

// The pixels whose centers lie in the MTA's bounding box in view i: an upper bound of what it covers
// there, and what a small-triangle path would have to visit.
int64_t footprint(const PmrParams& P, const PmrMta& m, int i) {
  const int64_t f = P.view_coord[i];
  int64_t xlo = INT64_MAX, xhi = INT64_MIN, ylo = INT64_MAX, yhi = INT64_MIN;
  for (int k = 0; k < 3; ++k) {
    const int64_t x = int64_t(m.x0[k]) + f * m.dx[k];
    xlo = std::min(xlo, x), xhi = std::max(xhi, x), ylo = std::min<int64_t>(ylo, m.y[k]),
    yhi = std::max<int64_t>(yhi, m.y[k]);
  }
  return centers_in(xlo, xhi, PMR_X_ONE, P.view_w) * centers_in(ylo, yhi, PMR_Y_ONE, P.view_h);
}

}  // namespace

void print_queue_stats(const Pipeline& pipeline, const StageTimes& t) {
  const PmrParams P = pipeline.read_params();
  const std::vector<PmrMta> mtas = pipeline.read_mtas();
  std::vector<uint32_t> offsets, queue;
  pipeline.read_tile_queues(offsets, queue);
  std::vector<uint32_t> entries(mtas.size(), 0);
  for (uint32_t id : queue)
    if (id < entries.size()) ++entries[id];
  Histogram per_mta({1, 2, 4, 8, 16, 32, 64}), per_tile({0, 4, 16, 64, 256, 1024, 4096});
  Histogram views({1, 4, 16, 48, 96}), pixels({0, 1, 2, 4, 8, 16, 64, 256, 1024}),
      voxels({0, 4, 16, 64, 256, 1024, 16384});
  uint64_t bbox_voxels = 0;
  for (size_t i = 0; i < mtas.size(); ++i) {
    const PmrMta& m = mtas[i];
    per_mta.add(entries[i]);
    views.add(uint64_t(m.view_hi - m.view_lo + 1));
    uint64_t all = 0;
    for (int v = m.view_lo; v <= m.view_hi; ++v) {
      const int64_t px = footprint(P, m, v);
      pixels.add(uint64_t(px));
      all += uint64_t(px);
    }
    voxels.add(all);
    bbox_voxels += all;
  }
  for (size_t k = 0; k + 1 < offsets.size(); ++k) per_tile.add(offsets[k + 1] - offsets[k]);
  std::printf("# queue stats of the last frame: %zu MTAs, %zu tile-queue entries in %d x %d x %d tiles\n", mtas.size(),
              queue.size(), P.tiles_x, P.tiles_y, P.tiles_v);
  per_mta.print("tile-queue entries per MTA");
  per_tile.print("entries per 3D tile");
  views.print("views per MTA");
  pixels.print("bounding-box pixel centers per (MTA, view)");
  voxels.print("bounding-box voxels per MTA");
  const double n = std::max<double>(1.0, double(mtas.size())), q = std::max<double>(1.0, double(queue.size()));
  std::printf(
      "#   per unit: setup %.1f ns/MTA; tile %.1f ns/MTA, %.1f ns/entry; fine %.1f ns/entry, %.2f ns per "
      "bounding-box voxel\n",
      1e6 * (t.vertex + t.setup) / n, 1e6 * t.bin / n, 1e6 * t.bin / q, 1e6 * t.fine / q,
      1e6 * t.fine / std::max<double>(1.0, double(bbox_voxels)));
}

}  // namespace pmr
