// The display's subpixel-to-view map (DESIGN section 5), exact for any display parameters given as
// decimals (up to 18 significant digits, optional exponent) or fractions.
//
// A literal float evaluation of floor(frac(t) * N) picks the wrong view wherever t * N is an integer
// (a third of all subpixels for some presets), and a real panel's calibration (L = 18.6578963681 ...)
// accumulates any rounding over hundreds of lenses. So with L = a/b, tan(alpha) = c/d, offset = e/f:
//   N t = (P_s - R_i) / Den,  Den = a d f,  P_s = N b d f s (s = 3j + k),  R_i = N b (3 i c f + e d),
// all exact integers (WideInt: up to ~220 bits). With P_s = qP Den + rP and R_i = qR Den + rR
// (0 <= r < Den): floor(N t) = qP - qR - (rP < rR). The tables hold qP, qR mod N and, instead of the
// wide remainders, their ranks among all column and row remainders: equal remainders get equal ranks,
// so the kernels' 32-bit comparison decides every subpixel exactly as the wide one would, ties included.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numeric>

#include "pmr/error.h"
#include "pmr/limits.h"
#include "pmr/rig.h"
#include "rig/wide_int.h"

namespace pmr {

namespace {

typedef __int128 i128;

Rational reduced(i128 num, i128 den, const std::string& what) {
  if (den == 0) throw Error("invalid " + what + ": division by zero");
  if (den < 0) num = -num, den = -den;
  i128 a = num < 0 ? -num : num, b = den;
  while (b != 0) {
    i128 t = a % b;
    a = b;
    b = t;
  }
  if (a > 1) num /= a, den /= a;
  const i128 lim = i128(1) << 62;
  if (num > lim || -num > lim || den > lim)
    throw Error("invalid " + what + ": too many digits for an exact fraction (at most 18 significant digits)");
  return Rational{int64_t(num), int64_t(den)};
}

// Parses an optionally signed decimal with an optional exponent ("16", "-0.0833", ".5", "1.5e-3") as an
// exact fraction num / den. At most 18 significant digits; the exponent moves the point.
bool parse_decimal(const std::string& s, i128& num, i128& den) {
  size_t i = 0;
  bool neg = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
  num = 0;
  den = 1;
  int digits = 0, scale = 0;  // value = num * 10^-scale
  bool frac = false, any = false;
  for (; i < s.size() && s[i] != 'e' && s[i] != 'E'; ++i) {
    if (s[i] == '.' && !frac) {
      frac = true;
      continue;
    }
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
    any = true;
    if (num == 0 && s[i] == '0') {  // leading zeros are not significant
      if (frac) ++scale;
      continue;
    }
    if (++digits > 18) return false;
    num = num * 10 + (s[i] - '0');
    if (frac) ++scale;
  }
  if (!any) return false;
  if (i < s.size()) {  // exponent
    ++i;
    bool eneg = false;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) eneg = s[i++] == '-';
    if (i >= s.size()) return false;
    int e = 0;
    for (; i < s.size(); ++i) {
      if (!std::isdigit(static_cast<unsigned char>(s[i])) || e > 100) return false;
      e = e * 10 + (s[i] - '0');
    }
    scale += eneg ? e : -e;
  }
  // num and den below 2^62 (products of two stay inside 128 bits; the encoder's wide integers hold
  // three of them)
  const i128 lim = i128(1) << 62;
  for (; scale > 0; --scale)
    if ((den *= 10) >= lim) return false;
  for (; scale < 0; ++scale)
    if ((num *= 10) >= lim) return false;
  if (neg) num = -num;
  return true;
}

}  // namespace

Rational parse_rational(const std::string& text, const std::string& what) {
  const size_t slash = text.find('/');
  i128 n1, d1, n2 = 1, d2 = 1;
  const bool ok = slash == std::string::npos
                      ? parse_decimal(text, n1, d1)
                      : parse_decimal(text.substr(0, slash), n1, d1) && parse_decimal(text.substr(slash + 1), n2, d2);
  if (!ok)
    throw Error("invalid " + what + " '" + text +
                "': expected a number (at most 18 significant digits) or a fraction like 1/18");
  return reduced(n1 * d2, d1 * n2, what);
}

Rational default_offset(const Rational& lens_pitch, int views) {
  // -L / (2N): N t lands half-way between view boundaries (DESIGN section 5). Only the command line's
  // lens pitch gets this default (presets and calibrations give their offset): reported as that option,
  // not as an offset nobody gave.
  try {
    return reduced(-i128(lens_pitch.num), i128(2) * lens_pitch.den * views, "offset");
  } catch (const Error&) {
    throw Error("invalid --lens-pitch " + to_string(lens_pitch) + ": the default offset -L/(2N) for " +
                std::to_string(views) + " views has too many digits to be exact; give --offset too");
  }
}

std::string to_string(const Rational& r) {
  return r.den == 1 ? std::to_string(r.num) : std::to_string(r.num) + "/" + std::to_string(r.den);
}

namespace {

// The exact integers of the header comment. With subpixel cells the offset moves to the column side:
// t = (3j - o/G - 3 i c/d) / (a/b) with G = 10^14, so Den = a d G, P = N b d (3j G - o), R_i = 3 N b c G i.
struct Phase {
  WideInt den, p1, r0, dr;  // Den, P_1 (P_s = s P_1), R_0, R_{i+1} - R_i
  bool cells = false;
  WideInt cell_scale;  // N b d (cells: P = cell_scale (3j G - o))
};

constexpr int64_t kCellDenominator = 100000000000000;  // 10^14

Phase phase_of(const Display& display, int views) {
  const Rational &L = display.lens_pitch, &T = display.tan_slant, &O = display.offset;
  Phase ph;
  if (!display.cell_offsets.empty()) {
    ph.cells = true;
    ph.den = WideInt(L.num) * T.den * kCellDenominator;
    ph.cell_scale = WideInt(views) * L.den * T.den;
    ph.p1 = ph.cell_scale * 3 * kCellDenominator;  // per pixel j (3 subpixels)
    ph.r0 = WideInt(0);
    ph.dr = WideInt(3) * views * L.den * T.num * kCellDenominator;
  } else {
    ph.den = WideInt(L.num) * T.den * O.den;
    ph.p1 = WideInt(views) * L.den * T.den * O.den;
    ph.r0 = WideInt(views) * L.den * O.num * T.den;
    ph.dr = WideInt(3) * views * L.den * T.num * O.den;
  }
  if (display.phase_sign < 0) {  // N (-t) = (-P_s + R_i) / Den
    ph.p1 = WideInt(0) - ph.p1;
    ph.r0 = WideInt(0) - ph.r0;
    ph.dr = WideInt(0) - ph.dr;
    ph.cell_scale = WideInt(0) - ph.cell_scale;
  }
  return ph;
}

// With cells: P for pixel column j, subpixel k in row class c.
WideInt cell_column_value(const Display& display, const Phase& ph, int j, int k, int c) {
  const int64_t o = display.cell_offsets[size_t((c * 2 + j % 2) * 3 + k)];
  return ph.cell_scale * (3 * int64_t(j)) * kCellDenominator - ph.cell_scale * o;
}

int mod_n(int64_t q, int n) { return int(((q % n) + n) % n); }

// The phase position of subpixel column s = 3j + k: s itself, or 3j + 2 - k on a BGR panel. The map
// is its own inverse.
size_t phase_position(const Display& display, size_t s) { return display.subpixel_bgr ? s - s % 3 + (2 - s % 3) : s; }

}  // namespace

PmrEncodeParams make_encode_params(const Display& display, int views, int view_w, int view_h) {
  if (display.width < 1 || display.height < 1 || display.width > kMaxDisplaySide || display.height > kMaxDisplaySide)
    throw Error("invalid --display: each side must be 1.." + std::to_string(kMaxDisplaySide));
  if (display.lens_pitch.num <= 0) throw Error("invalid --lens-pitch: must be positive");
  for (const Rational* r : {&display.lens_pitch, &display.tan_slant, &display.offset})
    if (r->den <= 0) throw InternalError("display fraction with a non-positive denominator");
  if (display.phase_sign != 1 && display.phase_sign != -1) throw InternalError("phase sign must be +1 or -1");
  PmrEncodeParams p{};
  p.display_w = display.width;
  p.display_h = display.height;
  p.views = views;
  p.view_w = view_w;
  p.view_h = view_h;
  p.reversed = display.reversed ? 1 : 0;
  p.bilinear = display.bilinear ? 1 : 0;
  p.blend = display.blend_views ? 1 : 0;
  p.cell_rows = display.cell_offsets.empty() ? 1 : display.cell_rows;
  if (!display.cell_offsets.empty() &&
      (display.cell_rows < 1 || display.cell_rows > 4 || display.cell_offsets.size() != size_t(display.cell_rows) * 6))
    throw InternalError("subpixel cell offsets do not match their row classes");
  if (display.blend_views && display.bilinear) throw Error("--blend-views and --bilinear cannot be combined");
  return p;
}

void make_encode_tables(const Display& display, const PmrEncodeParams& p, std::vector<PmrEncodeColumn>& columns,
                        std::vector<PmrEncodeRow>& rows) {
  const Phase ph = phase_of(display, p.views);
  const double den_d = ph.den.to_double();
  const size_t width3 = size_t(3) * p.display_w;
  columns.resize(width3 * size_t(p.cell_rows));
  rows.resize(size_t(p.display_h));
  // Remainders of every column and row, stepped exactly (one wide division each for the steps).
  std::vector<std::pair<WideInt, int>> rems(columns.size());  // (remainder, +column index or -(row index) - 1)
  rems.reserve(columns.size() + rows.size());
  WideInt q1, r1, q, r;
  ph.p1.floor_divmod(ph.den, q1, r1);
  const int64_t q1n = q1.to_int64();
  int64_t qp = 0;
  WideInt rp(0);
  for (size_t pos = 0; pos < (ph.cells ? 0 : columns.size()); ++pos) {  // phase positions in order
    if (pos > 0) {
      qp += q1n;
      rp = rp + r1;
      if (rp >= ph.den) rp = rp - ph.den, ++qp;
    }
    const size_t s = phase_position(display, pos);  // the subpixel whose phase sits there (an involution)
    PmrEncodeColumn& c = columns[s];
    c.a_mod_n = mod_n(qp, p.views);
    c.px = int32_t((int64_t(2 * s + 1) * p.view_w) / (int64_t(6) * p.display_w));
    c.phase_frac = float(rp.to_double() / den_d);
    rems[s] = {rp, int(s)};
  }
  if (ph.cells) {  // every column of every row class on its own (one wide division each)
    for (size_t e = 0; e < columns.size(); ++e) {
      const int c = int(e / width3), s = int(e % width3), j = s / 3, k = s % 3;
      WideInt qc, rc;
      cell_column_value(display, ph, j, k, c).floor_divmod(ph.den, qc, rc);
      PmrEncodeColumn& col = columns[e];
      col.a_mod_n = mod_n(qc.to_int64(), p.views);
      col.px = int32_t((int64_t(2 * s + 1) * p.view_w) / (int64_t(6) * p.display_w));
      col.phase_frac = float(rc.to_double() / den_d);
      rems[e] = {rc, int(e)};
    }
  }
  WideInt qd, rd;
  ph.dr.floor_divmod(ph.den, qd, rd);
  ph.r0.floor_divmod(ph.den, q, r);
  const int64_t qdn = qd.to_int64();
  int64_t qr = q.to_int64();
  for (size_t i = 0; i < rows.size(); ++i) {
    if (i > 0) {
      qr += qdn;
      r = r + rd;
      if (r >= ph.den) r = r - ph.den, ++qr;
    }
    PmrEncodeRow& row = rows[i];
    row.q_mod_n = mod_n(qr, p.views);
    row.py = int32_t((int64_t(2 * i + 1) * p.view_h) / (int64_t(2) * p.display_h));
    row.phase_frac = float(r.to_double() / den_d);
    rems.push_back({r, -int(i) - 1});
  }
  // Ranks of the remainders (equal remainders, equal ranks).
  std::sort(rems.begin(), rems.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  int32_t rank = 0;
  for (size_t k = 0; k < rems.size(); ++k) {
    if (k > 0 && rems[k - 1].first < rems[k].first) ++rank;
    const int idx = rems[k].second;
    if (idx >= 0) columns[size_t(idx)].b = rank;
    else rows[size_t(-idx - 1)].s = rank;
  }
}

int encode_view_index(const Display& display, int views, int j, int i, int k) {
  // Direct: N t = (P_s - R_i) / Den as one wide fraction, v = floor(N t) mod N.
  const Phase ph = phase_of(display, views);
  const WideInt column = ph.cells ? cell_column_value(display, ph, j, k, (display.height - 1 - i) % display.cell_rows)
                                  : ph.p1 * int64_t(phase_position(display, 3 * size_t(j) + size_t(k)));
  const WideInt num = column - (ph.r0 + ph.dr * i);
  WideInt q, r;
  num.floor_divmod(ph.den, q, r);
  int v = mod_n(q.to_int64(), views);
  if (display.reversed) v = views - 1 - v;
  return v;
}

}  // namespace pmr
