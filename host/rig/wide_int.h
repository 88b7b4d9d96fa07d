// A small fixed-width signed integer (sign and 320-bit magnitude) for the encoder's exact arithmetic:
// display parameters given as decimals of up to 18 digits make the common denominator of DESIGN
// section 5's phase about 200 bits wide. Only what the encoder tables need: products of 64-bit
// factors, sums, comparisons and one floor division. Overflow throws pmr::Error (it cannot happen
// for the inputs parse_rational accepts: 3 x 64 + 28 bits at most).
#pragma once
#include <cstdint>

namespace pmr {

class WideInt {
 public:
  WideInt() = default;
  explicit WideInt(int64_t v);

  WideInt operator+(const WideInt& o) const;
  WideInt operator-(const WideInt& o) const;
  WideInt operator*(int64_t m) const;
  bool operator<(const WideInt& o) const { return compare(o) < 0; }
  bool operator>=(const WideInt& o) const { return compare(o) >= 0; }
  bool operator==(const WideInt& o) const { return compare(o) == 0; }
  bool negative() const { return neg_ && !zero(); }
  bool zero() const;
  int compare(const WideInt& o) const;
  // The value as a double (rounded).
  double to_double() const;
  // The value as int64; throws when it does not fit.
  int64_t to_int64() const;

  // Floor division by d > 0: *this = q d + r with 0 <= r < d.
  void floor_divmod(const WideInt& d, WideInt& q, WideInt& r) const;

 private:
  static constexpr int kLimbs = 5;
  bool neg_ = false;
  uint64_t mag_[kLimbs] = {0, 0, 0, 0, 0};

  static int compare_mag(const uint64_t* a, const uint64_t* b);
  static void add_mag(const uint64_t* a, const uint64_t* b, uint64_t* out);  // throws on overflow
  static void sub_mag(const uint64_t* a, const uint64_t* b, uint64_t* out);  // a >= b
};

}  // namespace pmr
