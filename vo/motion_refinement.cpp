#include "vo/motion_refinement.h"

#include "common/numbers.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif


namespace kestrel::vo {
namespace {

using Matrix26d = Eigen::Matrix<double, 2, 6>;

// so3::hat's matrix, here so that the compiler sees it (the products with it are the same).
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

struct Projection {
  Eigen::Vector2d pixel;
  Eigen::Matrix<double, 2, 3> J;  // d pixel / d point
};

// Projection of X and its Jacobian; for ESM the Jacobian is taken halfway to the measurement,
// the pixel the projection reaches at the optimum (at the same depth).
inline Projection project(const Eigen::Vector3d& X, const PinholeCamera& cam,
                   const Eigen::Vector2d& measured, bool esm) {
  Projection p;
  const double iz = 1.0 / X.z();
  p.pixel = Eigen::Vector2d(cam.fx * X.x() * iz + cam.cx, cam.fy * X.y() * iz + cam.cy);
  const Eigen::Vector2d at = esm ? 0.5 * (p.pixel + measured) : p.pixel;
  p.J << cam.fx * iz, 0.0, -(at.x() - cam.cx) * iz, 0.0, cam.fy * iz, -(at.y() - cam.cy) * iz;
  return p;
}

// An image residual: point X (in the frame of the measured pixel) projected against the
// measured pixel, and g, the image motion per metre of X's depth in its own frame (dX_dz, the
// point's motion per metre of that depth). linearise() and the pixel-noise estimate share it.
struct ImageResidual {
  Projection pr;
  Eigen::Vector2d r, g;
};

inline ImageResidual image_residual(const Eigen::Vector3d& X, const Eigen::Vector3d& dX_dz,
                                    const Eigen::Vector2d& measured, const PinholeCamera& cam, bool esm) {
  ImageResidual ir;
  ir.pr = project(X, cam, measured, esm);
  ir.r = ir.pr.pixel - measured;
  ir.g = ir.pr.J * dX_dz;
  return ir;
}

// The normal equations, upper triangles only. The image and depth residuals are kept apart
// because their information shares differ (see add()): information = share * H_image + H_depth.
struct Accumulator {
  Matrix6d H_image = Matrix6d::Zero();
  Matrix6d H_depth = Matrix6d::Zero();
  Matrix6d H_dense = Matrix6d::Zero();
  int dense = 0;
  Vector6d g = Vector6d::Zero();
  double cost = 0.0;         // robust, whitened
  double sq_px = 0.0;        // unwhitened squared pixel error
  int residuals = 0;
};

// H += w * J^T J, written out: Eigen's rankUpdate takes its general matrix-product path for
// these tiny sizes, several times slower. Only the upper triangle is read (full()); the whole
// matrix is updated because fixed-length columns vectorise and a triangle's ragged loops did
// not, and each upper entry still sees exactly the same operations in the same order.
template <int Rows>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void rank_update(Matrix6d& H, const Eigen::Matrix<double, Rows, 6>& J, double w) {
  double* h = H.data();  // column-major
#if defined(__SSE2__)
  // Each column in three registers, which receive row 0's term and then row 1's, the order
  // of the scalar loop below.
  __m128d c[Rows][3];
  for (int r = 0; r < Rows; ++r)
    for (int p = 0; p < 3; ++p) c[r][p] = _mm_set_pd(J(r, 2 * p + 1), J(r, 2 * p));
  for (int j = 0; j < 6; ++j) {
    __m128d a[Rows];
    for (int r = 0; r < Rows; ++r) a[r] = _mm_set1_pd(w * J(r, j));
    for (int p = 0; p < 3; ++p) {
      __m128d x = _mm_loadu_pd(h + 6 * j + 2 * p);
      for (int r = 0; r < Rows; ++r) x = _mm_add_pd(x, _mm_mul_pd(a[r], c[r][p]));
      _mm_storeu_pd(h + 6 * j + 2 * p, x);
    }
  }
#else
  for (int r = 0; r < Rows; ++r) {
    double col[6];
    for (int i = 0; i < 6; ++i) col[i] = J(r, i);
    for (int j = 0; j < 6; ++j) {
      const double a = w * J(r, j);
      for (int i = 0; i < 6; ++i) h[6 * j + i] += a * col[i];
    }
  }
#endif
}

// Adds one scalar residual r with Jacobian J and standard deviation sigma.
void add_scalar(Accumulator& acc, double r, const Eigen::Matrix<double, 1, 6>& J, double sigma,
                const RefinementOptions& o) {
  const double rw = r / sigma;
  const double e = std::abs(rw);
  double weight = 1.0, rho = e * e;
  if (o.huber_px > 0.0 && e > o.huber_px) {
    weight = o.huber_px / e;
    rho = 2.0 * o.huber_px * e - o.huber_px * o.huber_px;
  }
  const Eigen::Matrix<double, 1, 6> Jw = J / sigma;
  rank_update<1>(acc.H_depth, Jw, weight);
  acc.g.noalias() += weight * Jw.transpose() * rw;
  acc.cost += rho;
}

// Adds one residual r = pixel(T) - measured with Jacobian J (2x6), whitened by pixel noise
// sigma and depth noise along g (the image motion per metre of depth of the projected point).
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void add(Accumulator& acc, const Eigen::Vector2d& r, const Matrix26d& J, const Eigen::Vector2d& g,
         double sigma_z, const RefinementOptions& o) {
  const double s = o.pixel_sigma;
  Eigen::Matrix2d W = Eigen::Matrix2d::Identity() / s;  // Sigma^-1/2
  if (o.depth_weighted && sigma_z > 0.0) {
    const double gn2 = g.squaredNorm();
    if (gn2 > 1e-18) {
      const Eigen::Vector2d u = g / std::sqrt(gn2);
      const double along = std::sqrt(s * s + sigma_z * sigma_z * gn2);
      W = (Eigen::Matrix2d::Identity() - u * u.transpose()) / s + u * u.transpose() / along;
    }
  }
  const Eigen::Vector2d rw = W * r;
  const Matrix26d Jw = W * J;
  const double e = rw.norm();
  double weight = 1.0, rho = e * e;
  if (o.huber_px > 0.0 && e > o.huber_px) {
    weight = o.huber_px / e;
    rho = 2.0 * o.huber_px * e - o.huber_px * o.huber_px;
  }
  rank_update<2>(acc.H_image, Jw, weight);
  acc.g.noalias() += weight * Jw.transpose() * rw;
  acc.cost += rho;
  acc.sq_px += r.squaredNorm();
  ++acc.residuals;
}

Matrix6d full(const Matrix6d& upper) { return upper.selfadjointView<Eigen::Upper>(); }

Matrix6d hessian(const Accumulator& acc) { return full(acc.H_image + acc.H_depth + acc.H_dense); }

// Each measurement counted once: a reprojection residual involves two noisy pixels (the measured
// one and the ray the point lies on), and the two directions of a bidirectional refinement
// measure the same pair again.
Matrix6d information(const Accumulator& acc, const RefinementOptions& o) {
  const double share = o.bidirectional ? 0.25 : 0.5;
  return full(share * acc.H_image + acc.H_depth + acc.H_dense);
}

// One residual as linearise() computes it, before whitening: a reprojection (kImage: r, J, g,
// sigma_z as add() takes them) or a depth residual (kDepth: r(0), Jd, sigma as add_scalar()).
struct RawResidual {
  enum Kind : uint8_t { kImage, kDepth } kind = kImage;
  Eigen::Vector2d r, g;
  Matrix26d J;
  Eigen::Matrix<double, 1, 6> Jd;
  double sigma = 0.0;  // sigma_z for an image residual
};

// The dense point-to-plane residuals, linearised once at the refinement's start T0 (the feature
// estimate): each current grid point X = R q + p against the plane of the reference grid cell it
// projects into, weighted (Huber) there. The residuals are nearly linear in the pose over the
// few millimetres the refinement moves, so the term is kept as the quadratic
// c0 + 2 g^T d + d^T H d in d = T boxminus T0, one pass over the grid per refinement.
struct DenseQuadratic {
  Matrix6d H = Matrix6d::Zero();  // upper triangle
  Vector6d g = Vector6d::Zero();
  double cost = 0.0;
  int residuals = 0;
  Eigen::Isometry3d T0 = Eigen::Isometry3d::Identity();
};

DenseQuadratic linearise_dense(const DenseTerm& d, const PinholeCamera& cam, const Eigen::Isometry3d& T) {
  DenseQuadratic out;
  out.T0 = T;
  const DenseOptions& o = d.options;
  const DenseDepth& ref = *d.ref;
  const DenseDepth& cur = *d.cur;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f p = T.translation().cast<float>();
  const float cos_max = static_cast<float>(std::cos(o.max_normal_angle_deg * kPi / 180.0));
  const float floor2 = static_cast<float>(1e-6 * o.sigma_floor_mm * o.sigma_floor_mm);
  const float max_d2 = static_cast<float>(o.max_distance_m * o.max_distance_m);
  const float k2 = static_cast<float>(d.sigma_z_coeff * d.sigma_z_coeff);
  const float huber = static_cast<float>(o.huber_sigmas);
  const float inv_s = 1.0f / float(ref.scale);
  const float fx = float(cam.fx), fy = float(cam.fy), cx = float(cam.cx), cy = float(cam.cy);
  // Without distortion the cell follows from the pinhole pixel alone.
  for (int y = 0; y < cur.height; y += o.stride) {
    for (int x = 0; x < cur.width; x += o.stride) {
      const size_t i = static_cast<size_t>(y * cur.width + x);
      const Eigen::Vector3f& nq = cur.normals[i];
      if (nq.z() == 0.0f) continue;  // invalid (zero), or exactly grazing: skipped alike
      const Eigen::Vector3f& q = cur.points[i];
      const Eigen::Vector3f X = R * q + p;
      if (!(X.z() > 1e-3f)) continue;
      float u = fx * X.x() / X.z() + cx, v = fy * X.y() / X.z() + cy;
      if (d.use_distortion) {
        const Eigen::Vector2d raw = cam.distort(static_cast<double>(u), static_cast<double>(v));
        u = static_cast<float>(raw.x());
        v = static_cast<float>(raw.y());
      }
      const float fu = std::floor((u + 0.5f) * inv_s), fv = std::floor((v + 0.5f) * inv_s);
      if (!(fu >= 0.0f && fv >= 0.0f && fu < float(ref.width) && fv < float(ref.height))) continue;
      const size_t j = static_cast<size_t>(fv) * static_cast<size_t>(ref.width) + static_cast<size_t>(fu);
      const Eigen::Vector3f& n = ref.normals[j];
      if (n.z() == 0.0f) continue;
      const Eigen::Vector3f diff = X - ref.points[j];
      if (diff.squaredNorm() > max_d2) continue;
      if ((R * nq).dot(n) < cos_max) continue;
      const float zp = ref.points[j].z(), zq = q.z();
      const float inv_sigma = 1.0f / std::sqrt(k2 * (zp * zp * zp * zp + zq * zq * zq * zq) + floor2);
      const float rw = n.dot(diff) * inv_sigma;
      // d r / d[dp; dtheta] = [n^T, -n^T R [q]x] = [n^T, (q x R^T n)^T].
      const Eigen::Vector3f m = q.cross(R.transpose() * n);
      Eigen::Matrix<double, 1, 6> Jw;
      Jw << static_cast<double>(n.x() * inv_sigma), static_cast<double>(n.y() * inv_sigma),
          static_cast<double>(n.z() * inv_sigma), static_cast<double>(m.x() * inv_sigma),
          static_cast<double>(m.y() * inv_sigma), static_cast<double>(m.z() * inv_sigma);
      const float e = std::abs(rw);
      double weight = o.weight, rho = double(e) * double(e);
      if (huber > 0.0f && e > huber) {
        weight *= double(huber / e);
        rho = 2.0 * double(huber) * double(e) - double(huber) * double(huber);
      }
      rank_update<1>(out.H, Jw, weight);
      out.g.noalias() += (weight * double(rw)) * Jw.transpose();
      out.cost += o.weight * rho;
      ++out.residuals;
    }
  }
  return out;
}

// Adds the dense quadratic at pose T.
void add_dense(Accumulator& acc, const DenseQuadratic& dq, const Eigen::Isometry3d& T) {
  const Vector6d d = se3::boxminus(T, dq.T0);
  const Matrix6d H = full(dq.H);
  const Vector6d Hd = H * d;
  acc.H_dense = dq.H;
  acc.g += dq.g + Hd;
  acc.cost += dq.cost + 2.0 * dq.g.dot(d) + d.dot(Hd);
  acc.dense = dq.residuals;
}

Accumulator linearise(const std::vector<Correspondence>& cs, const std::vector<int>& use,
                      const PinholeCamera& cam, const Eigen::Isometry3d& T,
                      const RefinementOptions& o, const DenseQuadratic* dense) {
  Accumulator acc;
  if (dense != nullptr) add_dense(acc, *dense, T);
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Matrix3d Rt = R.transpose();
  const Eigen::Vector3d p = T.translation();
  const bool esm = o.solver == Solver::kEsm;
  // In blocks of correspondences: their residuals first, then whitened and accumulated in
  // the same order as one at a time. The whitening is a chain of square roots and divisions;
  // in a loop of its own, several residuals' chains are in flight at once (the values and
  // the order of every sum are unchanged).
  constexpr size_t kBlock = 16;
  RawResidual block[3 * kBlock];
  size_t i_use = 0;
  while (i_use < use.size()) {
    size_t count = 0;
    for (const size_t end = std::min(use.size(), i_use + kBlock); i_use < end; ++i_use) {
      const Correspondence& c = cs[static_cast<size_t>(use[i_use])];
      // Reference point into the current image: Y = R^T (P - p).
      const Eigen::Vector3d Y = Rt * (c.ref_point - p);
      if (Y.z() > 1e-6) {
        const ImageResidual ir = image_residual(Y, Rt * (c.ref_point / c.ref_point.z()), c.cur_pixel, cam, esm);
        RawResidual& q = block[count++];
        q.kind = RawResidual::kImage;
        q.J.leftCols<3>() = -ir.pr.J * Rt;
        q.J.rightCols<3>() = ir.pr.J * skew(Y);
        q.r = ir.r;
        q.g = ir.g;
        q.sigma = c.ref_sigma_z;
      }
      // Current point in the reference frame: X = R Q + p.
      const Eigen::Vector3d X = R * c.cur_point + p;
      if (o.depth_residuals) {
        // Its distance along the reference ray against the reference depth: the information
        // the image residuals lack, which tells a sideways translation from a rotation.
        const Eigen::Vector3d u = c.ref_point.normalized();
        RawResidual& q = block[count++];
        q.kind = RawResidual::kDepth;
        q.Jd.leftCols<3>() = u.transpose();
        q.Jd.rightCols<3>() = -u.transpose() * R * skew(c.cur_point);
        q.sigma = std::sqrt(c.ref_sigma_z * c.ref_sigma_z + c.cur_sigma_z * c.cur_sigma_z + 1e-6 * o.depth_sigma_floor_mm * o.depth_sigma_floor_mm);
        q.r(0) = u.dot(X - c.ref_point);
      }
      if (!o.bidirectional) continue;
      if (X.z() > 1e-6) {
        const ImageResidual ir = image_residual(X, R * (c.cur_point / c.cur_point.z()), c.ref_pixel, cam, esm);
        RawResidual& q = block[count++];
        q.kind = RawResidual::kImage;
        q.J.leftCols<3>() = ir.pr.J;
        q.J.rightCols<3>() = -ir.pr.J * R * skew(c.cur_point);
        q.r = ir.r;
        q.g = ir.g;
        q.sigma = c.cur_sigma_z;
      }
    }
    for (size_t k = 0; k < count; ++k) {
      const RawResidual& q = block[k];
      if (q.kind == RawResidual::kImage) {
        add(acc, q.r, q.J, q.g, q.sigma, o);
      } else {
        add_scalar(acc, q.r(0), q.Jd, q.sigma, o);
      }
    }
  }
  return acc;
}

// The pixel noise the image residuals at T show. Each residual's component across its depth
// direction g (image_residual(), as linearise() forms them) is the difference of
// two noisy feature positions (variance 2 sigma^2 per axis), and the median of a squared
// standard normal is 0.4549. The median keeps the few bad matches that survive the outlier
// removal from inflating it. 0 when there are too few residuals to tell. A pass of its own,
// once per refinement: collecting the components in every linearise() cost more.
double pixel_sigma_from_residuals(const std::vector<Correspondence>& cs, const std::vector<int>& use,
                                  const PinholeCamera& cam, const Eigen::Isometry3d& T,
                                  const RefinementOptions& o) {
  constexpr size_t kMinResiduals = 20;
  std::vector<float> across_sq;
  across_sq.reserve(2 * use.size());
  const bool esm = o.solver == Solver::kEsm;
  auto collect = [&](const Eigen::Vector3d& X, const Eigen::Vector3d& dX_dz, const Eigen::Vector2d& measured) {
    if (X.z() <= 1e-6) return;
    const ImageResidual ir = image_residual(X, dX_dz, measured, cam, esm);
    const double gn2 = ir.g.squaredNorm();
    if (gn2 <= 1e-18) return;
    const double along_g = ir.r.dot(ir.g);
    across_sq.push_back(static_cast<float>(std::max(ir.r.squaredNorm() - along_g * along_g / gn2, 0.0)));
  };
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Matrix3d Rt = R.transpose();
  const Eigen::Vector3d p = T.translation();
  for (int i : use) {
    const Correspondence& c = cs[static_cast<size_t>(i)];
    collect(Rt * (c.ref_point - p), Rt * (c.ref_point / c.ref_point.z()), c.cur_pixel);
    if (o.bidirectional) collect(R * c.cur_point + p, R * (c.cur_point / c.cur_point.z()), c.ref_pixel);
  }
  if (across_sq.size() < kMinResiduals) return 0.0;
  auto mid = across_sq.begin() + static_cast<std::ptrdiff_t>(across_sq.size() / 2);
  std::nth_element(across_sq.begin(), mid, across_sq.end());
  return std::sqrt(double(*mid) / (2.0 * 0.4549));
}

}  // namespace

double reprojection_error_px(const Correspondence& c, const PinholeCamera& cam,
                             const Eigen::Isometry3d& T, bool bidirectional) {
  auto project_px = [&](const Eigen::Vector3d& X) {
    if (X.z() <= 1e-6) return Eigen::Vector2d(Eigen::Vector2d::Constant(1e9));
    return Eigen::Vector2d(cam.fx * X.x() / X.z() + cam.cx, cam.fy * X.y() / X.z() + cam.cy);
  };
  const double forward = (project_px(T.inverse() * c.ref_point) - c.cur_pixel).norm();
  if (!bidirectional) return forward;
  const double backward = (project_px(T * c.cur_point) - c.ref_pixel).norm();
  return std::max(forward, backward);
}

RefinementResult refine_motion(const std::vector<Correspondence>& cs, const std::vector<int>& use,
                               const PinholeCamera& cam, const Eigen::Isometry3d& T_ref_cur,
                               const RefinementOptions& o, const DenseTerm* dense, Information report) {
  RefinementResult result;
  Eigen::Isometry3d T = T_ref_cur;
  DenseQuadratic dq;
  if (dense != nullptr) dq = linearise_dense(*dense, cam, T);
  const DenseQuadratic* dqp = dense != nullptr ? &dq : nullptr;
  Accumulator acc = linearise(cs, use, cam, T, o, dqp);
  double lambda = 0.0;  // Levenberg-Marquardt damping, only once a step fails
  for (int it = 0; it < o.max_iterations && acc.residuals + acc.dense >= 6; ++it) {
    result.iterations = it + 1;
    Matrix6d A = hessian(acc);
    A.diagonal() *= 1.0 + lambda;
    const Vector6d delta = A.ldlt().solve(-acc.g);
    if (!delta.allFinite()) break;
    const Eigen::Isometry3d T_new = se3::boxplus(T, delta);
    const Accumulator acc_new = linearise(cs, use, cam, T_new, o, dqp);
    if (acc_new.residuals < acc.residuals || acc_new.cost > acc.cost) {
      lambda = lambda == 0.0 ? 1e-3 : lambda * 10.0;
      if (lambda > 1e3) break;
      continue;
    }
    lambda *= 0.1;
    if (lambda < 1e-6) lambda = 0.0;
    T = T_new;
    acc = acc_new;
    if (delta.head<3>().norm() < 1e-6 && delta.tail<3>().norm() < 1e-7) {  // a micrometre
      result.converged = true;
      break;
    }
  }
  if (!result.converged && acc.residuals + acc.dense >= 6) {
    // Stopped by the iteration limit or a step that no damping could make descend: a local
    // minimum to within what the data resolves.
    const Vector6d step = hessian(acc).ldlt().solve(-acc.g);
    result.converged = step.allFinite() && step.head<3>().norm() < 1e-4 && step.tail<3>().norm() < 1e-4;
  }
  result.T_ref_cur = T;
  if (report == Information::kReport) {
    // The information as the noise the residuals show would give it; the estimate itself
    // keeps the configured weighting, which the accuracy figures were tuned with.
    RefinementOptions measured = o;
    const double estimated = o.pixel_sigma_from_residuals ? pixel_sigma_from_residuals(cs, use, cam, T, o) : 0.0;
    if (estimated > 0.0) {
      measured.pixel_sigma = std::max(estimated, o.min_pixel_sigma);
      acc = linearise(cs, use, cam, T, measured, dqp);
    }
    result.information = information(acc, measured);
    result.pixel_sigma = measured.pixel_sigma;
  }
  result.dense_residuals = acc.dense;
  result.rms_error_px = acc.residuals > 0 ? std::sqrt(acc.sq_px / acc.residuals) : 0.0;
  return result;
}

}  // namespace kestrel::vo
