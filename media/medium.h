#pragma once
// The medium filling one region of a scene: homogeneous or a voxel grid, with its distance
// sampling strategy. A plain tagged struct: the tracer switches on the type once per ray
// segment, never per step.
#include "media/grid_medium.h"
#include "media/homogeneous.h"
#include "samplers/medium_distance.h"

namespace femto {

struct Medium {
  enum class Type { Homogeneous, Grid };
  Type type = Type::Homogeneous;
  HomogeneousMedium homogeneous;     ///< coefficients of a homogeneous medium; g for both types
  const GridMedium* grid = nullptr;  ///< owned by the Scene
  DistanceStrategy strategy;
  ConnectionSampling connection = ConnectionSampling::Collision;
  DirectionSampling direction = DirectionSampling::Phase;

  double g() const { return homogeneous.g; }
  /// Whether light can scatter or be absorbed here (a clear region needs no distance sampling).
  bool interacts() const { return type == Type::Grid || homogeneous.sigma_t() > 0; }
  /// Extinction coefficient at a point, 1/mm.
  double sigma_t_at(const Vec3& p) const {
    return type == Type::Grid ? grid->sigma_t_at(p) : homogeneous.sigma_t();
  }
  /// Refractive index at a point.
  double eta_at(const Vec3& p) const { return type == Type::Grid ? grid->eta_at(p) : homogeneous.eta; }
};

}  // namespace femto
