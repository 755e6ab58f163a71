#include "core/types.h"

namespace hairbench {

Affine3f interpolate_head(const Affine3f& a, const Affine3f& b, float s) {
  if (s >= 1.0f) return b;
  if (s <= 0.0f) return a;
  const Quatf qa(a.rotation());
  const Quatf qb(b.rotation());
  Affine3f out = Affine3f::Identity();
  out.linear() = qa.slerp(s, qb).toRotationMatrix();
  out.translation() = a.translation() + s * (b.translation() - a.translation());
  return out;
}

}  // namespace hairbench
