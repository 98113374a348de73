#pragma once
// Perfect specular reflection, two-sided, scaled by a colour (a Dirac delta: f and pdf are 0).
#include <cmath>

#include "core/bsdf/bsdf_sample.h"

namespace femto {

struct Mirror {
  RGB reflectance{1.0};

  bool sample(const Vec3& wo, BsdfSample& s) const {
    if (wo.z == 0.0 || !std::isfinite(wo.z)) return false;
    s.wi = Vec3(-wo.x, -wo.y, wo.z);
    s.pdf = 1.0;  // the only lobe
    s.weight = reflectance;
    s.delta = true;
    s.transmitted = false;
    return true;
  }
};

}  // namespace femto
