// The model-independent parts of the manifold laws (manifold_laws.h), compiled once.

#include "test/support/manifold_laws.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

namespace kestrel::test {

Eigen::Matrix<double, 9, 1> embed_rotation(const Eigen::Matrix3d& R) {
  return Eigen::Map<const Eigen::Matrix<double, 9, 1>>(R.data());
}

Eigen::VectorXd embed_pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::VectorXd v(12);
  v << embed_rotation(R), t;
  return v;
}

namespace laws {

std::string text(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s << v.transpose();
  return s.str();
}

Eigen::Index rank(const Eigen::MatrixXd& J, double threshold) {
  return Eigen::FullPivLU<Eigen::MatrixXd>(J).setThreshold(threshold).rank();
}

}  // namespace laws
}  // namespace kestrel::test
