#pragma once
// Spatial radius and temporal bandwidth of transient progressive photon mapping, pass by pass
// (seed 000 eq. 10, Supp. C): the kernel volume R^2 T shrinks by (j + alpha) / (j + 1) per pass,
// R^2 taking the power beta_R = 1 - beta_T and T the power beta_T:
//   R_{j+1}^2 = R_j^2 ((j + alpha) / (j + 1))^beta_R,   T_{j+1} = T_j ((j + alpha) / (j +
//   1))^beta_T.
// Bias ~ R^2 + T^2 ~ n^{-(1-alpha) beta_R} + n^{-2 (1-alpha) beta_T} balances at beta_T = 1/3;
// variance ~ 1 / (n R^2 T) ~ n^{-alpha}; the mean squared error then falls fastest, as n^{-4/7},
// at alpha = 4/7.
#include <cmath>

namespace femto {

/// `dims` is the spatial kernel's dimension: 2 for photons on surfaces (a disc), 1 for photon
/// beams (a 1-D kernel across the beam); the kernel volume is R^dims T.
class PpmSchedule {
 public:
  PpmSchedule(double radius_1, double bandwidth_1, double alpha, double beta_t, int dims = 2)
      : R_(radius_1), T_(bandwidth_1), alpha_(alpha), beta_t_(beta_t), dims_(dims) {}

  int pass() const { return j_; }  ///< current pass, from 1
  double radius() const { return R_; }
  double bandwidth() const { return T_; }
  void advance() {
    const double ratio = (j_ + alpha_) / (j_ + 1.0);
    R_ *= std::pow(ratio, (1.0 - beta_t_) / dims_);
    T_ *= std::pow(ratio, beta_t_);
    ++j_;
  }

 private:
  int j_ = 1;
  double R_, T_, alpha_, beta_t_;
  int dims_;
};

}  // namespace femto
