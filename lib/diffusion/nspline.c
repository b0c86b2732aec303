/*
** nspline.c — the interpolants of feature-curve attributes (Hnaidi et al.
** 2010, section 3.1): the natural cubic spline of the elevation ("a cubic
** spline to avoid unnatural piecewise linear ridge lines") and the
** linear interpolant of everything else, both in normalised arc length
** and constant beyond the end knots.
*/
#include "diffusion/diffusion.h"

/* The knot interval holding t: i with u[i] <= t < u[i + 1] (n >= 2,
** u[0] <= t < u[n - 1]). */
static size_t interval(const double *u, size_t n, double t) {
  size_t lo = 0, hi = n - 1;
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (u[mid] <= t)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* Thomas' algorithm on the tridiagonal system of the interior second
** derivatives: h_{i-1} m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_i m_{i+1} =
** 6 (d_i - d_{i-1}), d_i the secant slope of interval i. */
void oc_nspline_fit(const double *u, const double *v, size_t n, double *m,
                    double *work) {
  for (size_t i = 0; i < n; i++)
    m[i] = 0;
  if (n < 3) return;
  double *c = work, *r = work + n;
  for (size_t i = 1; i + 1 < n; i++) {
    double h0 = u[i] - u[i - 1], h1 = u[i + 1] - u[i];
    double d = 6 * ((v[i + 1] - v[i]) / h1 - (v[i] - v[i - 1]) / h0);
    double b = 2 * (h0 + h1), a = i > 1 ? h0 : 0;
    double den = b - a * (i > 1 ? c[i - 1] : 0);
    c[i] = h1 / den;
    r[i] = (d - a * (i > 1 ? r[i - 1] : 0)) / den;
  }
  m[n - 2] = r[n - 2];
  for (size_t i = n - 2; i-- > 1;)
    m[i] = r[i] - c[i] * m[i + 1];
}

double oc_nspline_eval(const double *u, const double *v, const double *m,
                       size_t n, double t) {
  if (n == 1 || t <= u[0]) return v[0];
  if (t >= u[n - 1]) return v[n - 1];
  size_t i = interval(u, n, t);
  double h = u[i + 1] - u[i], a = (u[i + 1] - t) / h, b = (t - u[i]) / h;
  return a * v[i] + b * v[i + 1] +
         ((a * a * a - a) * m[i] + (b * b * b - b) * m[i + 1]) * h * h / 6;
}

double oc_linear_eval(const double *u, const double *v, size_t n, double t) {
  if (n == 1 || t <= u[0]) return v[0];
  if (t >= u[n - 1]) return v[n - 1];
  size_t i = interval(u, n, t);
  double b = (t - u[i]) / (u[i + 1] - u[i]);
  return v[i] + b * (v[i + 1] - v[i]);
}
