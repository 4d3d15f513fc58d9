// Forward-mode automatic differentiation in float64: a value and its derivatives with respect to N
// inputs. The float64 reference's backward (reference_backward.cpp) differentiates its projection with
// it, so that the reference's gradients come from the forward's own formulas, not from a second,
// hand-derived copy of them: the GPU's hand-derived backward passes are checked against it.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace tilesplat::reference {

template <size_t N>
struct Dual {
  double v = 0;               // the value
  std::array<double, N> d{};  // d value / d input k

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT(google-explicit-constructor): a constant
  // Input `k` of the N, at `value`.
  static Dual input(double value, size_t k) {
    Dual x(value);
    x.d[k] = 1;
    return x;
  }
};

template <size_t N>
Dual<N> operator-(const Dual<N>& a) {
  Dual<N> r(-a.v);
  for (size_t k = 0; k < N; ++k) r.d[k] = -a.d[k];
  return r;
}
template <size_t N>
Dual<N> operator+(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v + b.v);
  for (size_t k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
template <size_t N>
Dual<N> operator-(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v - b.v);
  for (size_t k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
template <size_t N>
Dual<N> operator*(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v * b.v);
  for (size_t k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
template <size_t N>
Dual<N> operator/(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v / b.v);
  for (size_t k = 0; k < N; ++k) r.d[k] = (a.d[k] - r.v * b.d[k]) / b.v;
  return r;
}
template <size_t N>
Dual<N> operator+(const Dual<N>& a, double b) {
  return a + Dual<N>(b);
}
template <size_t N>
Dual<N> operator+(double a, const Dual<N>& b) {
  return Dual<N>(a) + b;
}
template <size_t N>
Dual<N> operator-(const Dual<N>& a, double b) {
  return a - Dual<N>(b);
}
template <size_t N>
Dual<N> operator-(double a, const Dual<N>& b) {
  return Dual<N>(a) - b;
}
template <size_t N>
Dual<N> operator*(const Dual<N>& a, double b) {
  Dual<N> r(a.v * b);
  for (size_t k = 0; k < N; ++k) r.d[k] = a.d[k] * b;
  return r;
}
template <size_t N>
Dual<N> operator*(double a, const Dual<N>& b) {
  return b * a;
}
template <size_t N>
Dual<N> operator/(const Dual<N>& a, double b) {
  return a * (1.0 / b);
}
template <size_t N>
Dual<N> operator/(double a, const Dual<N>& b) {
  return Dual<N>(a) / b;
}

// f(a) with f'(a): the chain rule's one step.
template <size_t N>
Dual<N> chain(const Dual<N>& a, double value, double derivative) {
  Dual<N> r(value);
  for (size_t k = 0; k < N; ++k) r.d[k] = derivative * a.d[k];
  return r;
}
template <size_t N>
Dual<N> exp(const Dual<N>& a) {
  const double e = std::exp(a.v);
  return chain(a, e, e);
}
template <size_t N>
Dual<N> sqrt(const Dual<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s);
}

}  // namespace tilesplat::reference
