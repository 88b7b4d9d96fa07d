#include "rig/wide_int.h"

#include "pmr/error.h"

namespace pmr {

namespace {
[[noreturn]] void overflow() { throw InternalError("exact display arithmetic overflowed 320 bits"); }
}  // namespace

WideInt::WideInt(int64_t v) {
  neg_ = v < 0;
  mag_[0] = neg_ ? uint64_t(0) - uint64_t(v) : uint64_t(v);
}

bool WideInt::zero() const {
  for (uint64_t l : mag_)
    if (l) return false;
  return true;
}

int WideInt::compare_mag(const uint64_t* a, const uint64_t* b) {
  for (int i = kLimbs - 1; i >= 0; --i)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}

void WideInt::add_mag(const uint64_t* a, const uint64_t* b, uint64_t* out) {
  unsigned __int128 carry = 0;
  for (int i = 0; i < kLimbs; ++i) {
    carry += (unsigned __int128)a[i] + b[i];
    out[i] = uint64_t(carry);
    carry >>= 64;
  }
  if (carry) overflow();
}

void WideInt::sub_mag(const uint64_t* a, const uint64_t* b, uint64_t* out) {
  uint64_t borrow = 0;
  for (int i = 0; i < kLimbs; ++i) {
    const uint64_t x = a[i], y = b[i];
    out[i] = x - y - borrow;
    borrow = (x < y) || (x - y < borrow) ? 1 : 0;
  }
}

int WideInt::compare(const WideInt& o) const {
  const bool a = negative(), b = o.negative();
  if (a != b) return a ? -1 : 1;
  const int m = compare_mag(mag_, o.mag_);
  return a ? -m : m;
}

WideInt WideInt::operator+(const WideInt& o) const {
  WideInt r;
  if (negative() == o.negative()) {
    add_mag(mag_, o.mag_, r.mag_);
    r.neg_ = negative();
  } else if (compare_mag(mag_, o.mag_) >= 0) {
    sub_mag(mag_, o.mag_, r.mag_);
    r.neg_ = negative();
  } else {
    sub_mag(o.mag_, mag_, r.mag_);
    r.neg_ = o.negative();
  }
  return r;
}

WideInt WideInt::operator-(const WideInt& o) const {
  WideInt n = o;
  n.neg_ = !o.negative() && !o.zero();
  return *this + n;
}

WideInt WideInt::operator*(int64_t m) const {
  const uint64_t um = m < 0 ? uint64_t(0) - uint64_t(m) : uint64_t(m);
  WideInt r;
  unsigned __int128 carry = 0;
  for (int i = 0; i < kLimbs; ++i) {
    carry += (unsigned __int128)mag_[i] * um;
    r.mag_[i] = uint64_t(carry);
    carry >>= 64;
  }
  if (carry) overflow();
  r.neg_ = (negative() != (m < 0)) && !r.zero();
  return r;
}

double WideInt::to_double() const {
  double x = 0.0;
  for (int i = kLimbs - 1; i >= 0; --i) x = x * 18446744073709551616.0 + double(mag_[i]);
  return negative() ? -x : x;
}

int64_t WideInt::to_int64() const {
  for (int i = 1; i < kLimbs; ++i)
    if (mag_[i]) overflow();
  if (mag_[0] > uint64_t(INT64_MAX)) overflow();
  return negative() ? -int64_t(mag_[0]) : int64_t(mag_[0]);
}

void WideInt::floor_divmod(const WideInt& d, WideInt& q, WideInt& r) const {
  if (d.negative() || d.zero()) throw InternalError("WideInt division by a non-positive number");
  // Binary long division of the magnitudes.
  WideInt qm, rm;
  for (int bit = kLimbs * 64 - 1; bit >= 0; --bit) {
    // rm = 2 rm + bit
    uint64_t carry = (mag_[bit / 64] >> (bit % 64)) & 1u;
    for (int i = 0; i < kLimbs; ++i) {
      const uint64_t next = rm.mag_[i] >> 63;
      rm.mag_[i] = (rm.mag_[i] << 1) | carry;
      carry = next;
    }
    if (carry) overflow();
    if (compare_mag(rm.mag_, d.mag_) >= 0) {
      sub_mag(rm.mag_, d.mag_, rm.mag_);
      qm.mag_[bit / 64] |= uint64_t(1) << (bit % 64);
    }
  }
  if (!negative() || rm.zero()) {
    q = qm;
    q.neg_ = negative() && !qm.zero();
    r = rm;
    return;
  }
  // negative with a remainder: q = -(qm + 1), r = d - rm
  q = qm + WideInt(1);
  q.neg_ = true;
  r = d - rm;
}

}  // namespace pmr
