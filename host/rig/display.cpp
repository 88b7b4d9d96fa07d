// The display's subpixel-to-view map (DESIGN section 5) in exact rational arithmetic.
//
// A literal float evaluation of floor(frac(t) * N) picks the wrong view wherever t * N is an integer
// (a third of all subpixels for some presets), so every display parameter is kept as an exact
// fraction and the kernel evaluates N t = (num_jk (3j + k) - num_i i - num_0) / den in int64.
#include <cctype>
#include <cmath>
#include <limits>
#include <numeric>

#include "pmr/error.h"
#include "pmr/rig.h"

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
  const i128 lim = i128(1) << 40;
  if (num > lim || -num > lim || den > lim)
    throw Error("invalid " + what + ": too many digits for an exact fraction");
  return Rational{int64_t(num), int64_t(den)};
}

// Parses an optionally signed decimal ("16", "-0.0833", ".5") as an exact fraction.
bool parse_decimal(const std::string& s, i128& num, i128& den) {
  size_t i = 0;
  bool neg = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
  num = 0;
  den = 1;
  int digits = 0;
  bool frac = false;
  for (; i < s.size(); ++i) {
    if (s[i] == '.' && !frac) {
      frac = true;
      continue;
    }
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
    if (++digits > 15) return false;
    num = num * 10 + (s[i] - '0');
    if (frac) den *= 10;
  }
  if (digits == 0) return false;
  if (neg) num = -num;
  return true;
}

i128 floor_div(i128 a, i128 b) {  // b > 0
  i128 q = a / b;
  if ((a % b != 0) && (a < 0)) --q;
  return q;
}

}  // namespace

Rational parse_rational(const std::string& text, const std::string& what) {
  const size_t slash = text.find('/');
  i128 n1, d1, n2 = 1, d2 = 1;
  const bool ok = slash == std::string::npos
                      ? parse_decimal(text, n1, d1)
                      : parse_decimal(text.substr(0, slash), n1, d1) &&
                            parse_decimal(text.substr(slash + 1), n2, d2);
  if (!ok) throw Error("invalid " + what + " '" + text + "': expected a number or a fraction like 1/18");
  return reduced(n1 * d2, d1 * n2, what);
}

std::string to_string(const Rational& r) {
  return r.den == 1 ? std::to_string(r.num) : std::to_string(r.num) + "/" + std::to_string(r.den);
}

PmrEncodeParams make_encode_params(const Display& display, int views, int view_w, int view_h) {
  if (display.width < 1 || display.height < 1 || display.width > 16384 || display.height > 16384)  // encode.cl indexes in 32 bits
    throw Error("invalid --display: each side must be 1..16384");
  if (display.lens_pitch.num <= 0) throw Error("invalid --lens-pitch: must be positive");
  const Rational& L = display.lens_pitch;
  const Rational& T = display.tan_slant;
  const Rational& O = display.offset;
  // N t = N (3j + k - 3 i T - O) / L = (num_jk (3j+k) - num_i i - num_0) / den
  const i128 num_jk = i128(views) * L.den * T.den * O.den;
  const i128 num_i = i128(3) * views * L.den * T.num * O.den;
  const i128 num_0 = i128(views) * L.den * O.num * T.den;
  const i128 den = i128(L.num) * T.den * O.den;
  const i128 a_i = num_i < 0 ? -num_i : num_i, a_0 = num_0 < 0 ? -num_0 : num_0;
  const i128 worst = num_jk * (3 * i128(display.width) + 3) + a_i * display.height + a_0;
  if (worst >= (i128(1) << 62) || den >= (i128(1) << 31))
    throw Error("display parameters need too many digits for exact subpixel evaluation; use simpler fractions");
  PmrEncodeParams p{};
  p.num_jk = int64_t(num_jk);
  p.num_i = int64_t(num_i);
  p.num_0 = int64_t(num_0);
  p.den = int64_t(den);
  p.display_w = display.width;
  p.display_h = display.height;
  p.views = views;
  p.view_w = view_w;
  p.view_h = view_h;
  p.reversed = display.reversed ? 1 : 0;
  p.bilinear = display.bilinear ? 1 : 0;
  return p;
}

void make_encode_tables(const PmrEncodeParams& p, std::vector<PmrEncodeColumn>& columns, std::vector<PmrEncodeRow>& rows) {
  columns.resize(size_t(3) * p.display_w);
  for (size_t s = 0; s < columns.size(); ++s) {
    const i128 n = i128(p.num_jk) * i128(s);
    const i128 a = floor_div(n, p.den);
    PmrEncodeColumn& c = columns[s];
    c.a_mod_n = int32_t(((a % p.views) + p.views) % p.views);
    c.b = int32_t(n - a * p.den);
    c.px = int32_t((i128(2 * s + 1) * p.view_w) / (i128(6) * p.display_w));
    c.pad = 0;
  }
  rows.resize(size_t(p.display_h));
  for (size_t i = 0; i < rows.size(); ++i) {
    const i128 n = i128(p.num_i) * i128(i) + p.num_0;
    const i128 q = floor_div(n, p.den);
    PmrEncodeRow& r = rows[i];
    r.q_mod_n = int32_t(((q % p.views) + p.views) % p.views);
    r.s = int32_t(n - q * p.den);
    r.py = int32_t((i128(2 * i + 1) * p.view_h) / (i128(2) * p.display_h));
    r.pad = 0;
  }
}

int encode_view_index(const Display& display, int views, int j, int i, int k) {
  // t = (3j + k - 3 i tan(alpha) - offset) / L as one fraction p / q, then v = floor(frac(t) N).
  const Rational &L = display.lens_pitch, &T = display.tan_slant, &O = display.offset;
  const i128 q0 = i128(T.den) * O.den;  // common denominator of the bracket
  const i128 p0 = (i128(3) * j + k) * q0 - i128(3) * i * T.num * O.den - i128(O.num) * T.den;
  const i128 p = p0 * L.den, q = q0 * L.num;  // divide by L = L.num / L.den
  const i128 frac_num = p - floor_div(p, q) * q;  // frac(t) = frac_num / q, in [0, 1)
  int v = int(floor_div(frac_num * views, q));
  if (v > views - 1) v = views - 1;
  if (display.reversed) v = views - 1 - v;
  return v;
}

}  // namespace pmr
