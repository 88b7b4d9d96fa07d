// Quilts in the Looking Glass convention (DESIGN section 6): all views tiled in one image, view 0 in
// the bottom-left tile, then left to right and upward; the file stem says the layout and the view's
// aspect (`_qs{columns}x{rows}a{aspect}`), which Looking Glass players parse to show it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace pmr {

struct QuiltLayout {
  int columns = 0, rows = 0;
};

// The largest image side a quilt may have (GPU texture limits of the players).
constexpr int kMaxQuiltSide = 16384;

// The layout for `views` tiles of view_w x view_h pixels: exactly views tiles when a factorization
// gives a quilt within 2:1 of square (the most square one; ties go to more columns), otherwise the
// fewest empty tiles among near-square layouts. 48 views of 420x560 -> 8x6, 45 of 819x455 -> 5x9.
// Throws pmr::Error (suggesting smaller views) when even the best layout exceeds kMaxQuiltSide.
QuiltLayout choose_quilt_layout(int views, int view_w, int view_h);

// Parses "CxR" (--quilt); throws on malformed text, fewer tiles than views, or a side over
// kMaxQuiltSide (the message suggests a layout that fits, if any).
QuiltLayout parse_quilt_layout(const std::string& text, int views, int view_w, int view_h);

// "{stem}_qs{C}x{R}a{aspect}" with the aspect (view width / height, physical) in at most 4
// decimals, trailing zeros dropped: 0.75 -> "a0.75", 166/93 -> "a1.7849".
std::string quilt_stem(const std::string& stem, const QuiltLayout& layout, double aspect);

// Tiles the view volume ([view][y][x][4] halves, row 0 at the top) into the quilt image
// (columns * view_w x rows * view_h, row 0 at the top); tiles without a view are transparent. If
// depth is given ([view][y][x]), quilt_depth receives the Z image, +infinity in empty tiles.
void assemble_quilt(const QuiltLayout& layout, int views, int view_w, int view_h, const uint16_t* volume,
                    const float* depth, std::vector<uint16_t>& quilt, std::vector<float>* quilt_depth);

}  // namespace pmr
