#include "embree_oracle.hpp"

#include <limits>

namespace oracle {

Hit Embree::intersect(sh::rt::Vec3 o, sh::rt::Vec3 d) const {
  RTCRayHit rh = scene_.intersect(o, d, std::numeric_limits<float>::min());
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return {rh.ray.tfar, static_cast<int>(rh.hit.primID), rh.hit.u, rh.hit.v};
}

}  // namespace oracle
