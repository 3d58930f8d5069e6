// Double-precision Eigen references of RLSD, KFD and the batch solution (5-10).
#include "demod_ref.h"

#include <Eigen/Dense>
#include <cmath>

namespace
{

using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;

Mat2 load(const double p[4])
{
  Mat2 m;
  m << p[0], p[1], p[2], p[3];
  return m;
}

void store(const Mat2 &m, double p[4])
{
  p[0] = m(0, 0);
  p[1] = m(0, 1);
  p[2] = m(1, 0);
  p[3] = m(1, 1);
}

}  // namespace

extern "C" void ref_rls_init(ref_rls_t *s, double lambda, double p0)
{
  s->w[0] = s->w[1] = 0.0;
  store(p0 * Mat2::Identity(), s->p);
  s->lambda = lambda;
}

extern "C" void ref_rls_step(ref_rls_t *s, double d, double ref_sin, double ref_cos)
{
  const Vec2 phi(ref_sin, ref_cos);
  Vec2 w(s->w[0], s->w[1]);
  Mat2 P = load(s->p);
  const double err = d - phi.dot(w);
  const Vec2 K = P * phi / (s->lambda + phi.dot(P * phi));
  w += K * err;
  P = (P - K * phi.transpose() * P) / s->lambda;
  s->w[0] = w(0);
  s->w[1] = w(1);
  store(P, s->p);
}

extern "C" void ref_kf_init(ref_kf_t *s, double q, double r, double p0)
{
  s->x[0] = s->x[1] = 0.0;
  store(p0 * Mat2::Identity(), s->p);
  s->q = q;
  s->r = r;
}

extern "C" void ref_kf_step(ref_kf_t *s, double z, double ref_sin, double ref_cos)
{
  const Mat2 A = Mat2::Identity();
  const Mat2 Q = s->q * Mat2::Identity();
  const Eigen::RowVector2d H(ref_sin, ref_cos);
  Vec2 x(s->x[0], s->x[1]);
  const Mat2 P = load(s->p);

  const Vec2 x_pred = A * x;
  const Mat2 P_pred = A * P * A.transpose() + Q;
  const double S = (H * P_pred * H.transpose())(0, 0) + s->r;
  const Vec2 K = P_pred * H.transpose() / S;
  x = x_pred + K * (z - (H * x_pred)(0, 0));
  const Mat2 M = Mat2::Identity() - K * H;
  const Mat2 P_new = M * P_pred * M.transpose() + K * s->r * K.transpose();

  s->x[0] = x(0);
  s->x[1] = x(1);
  store(P_new, s->p);
}

extern "C" int ref_wls_solve(const double *d, const double *ref_sin, const double *ref_cos,
                             size_t n, double lambda, double p0, double w[2], double p_out[4])
{
  if (d == nullptr || ref_sin == nullptr || ref_cos == nullptr || w == nullptr || n == 0 ||
      !(lambda > 0.0 && lambda <= 1.0)) {
    return -1;
  }
  const Eigen::Index rows = static_cast<Eigen::Index>(n) + (p0 > 0.0 ? 2 : 0);
  // Rows scaled by sqrt(lambda^(n-1-i)) turn (5-9) into an ordinary least-squares
  // problem; the prior adds two rows sqrt(lambda^n / p0) * I against a zero target.
  Eigen::MatrixXd G(rows, 2);
  Eigen::VectorXd y(rows);
  for (size_t i = 0; i < n; i++) {
    const double sw = std::sqrt(std::pow(lambda, static_cast<double>(n - 1 - i)));
    const auto r = static_cast<Eigen::Index>(i);
    G(r, 0) = sw * ref_sin[i];
    G(r, 1) = sw * ref_cos[i];
    y(r) = sw * d[i];
  }
  if (p0 > 0.0) {
    const double sp = std::sqrt(std::pow(lambda, static_cast<double>(n)) / p0);
    const auto r = static_cast<Eigen::Index>(n);
    G.row(r) << sp, 0.0;
    G.row(r + 1) << 0.0, sp;
    y(r) = 0.0;
    y(r + 1) = 0.0;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(G);
  if (qr.rank() < 2) {
    return -1;
  }
  const Vec2 sol = qr.solve(y);
  w[0] = sol(0);
  w[1] = sol(1);
  if (p_out != nullptr) {
    store((G.transpose() * G).inverse(), p_out);
  }
  return 0;
}
