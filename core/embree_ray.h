// @brief The Embree 3 ray set-up shared by the two Embree adapters: the
// reference renderer's scene (render/reference/embree_scene.cpp) and the exact mesh
// queries of the collision code (sim/collision/mesh_query.cpp).
//
// Header-only, and included ONLY by those two .cpp files: Embree is a heavy
// header that stays inside the few translation units that need it, and
// hp_core itself does not link Embree (the two libraries that include this do).
// It lives in core/ because it is below both render/ and sim/, which may not
// include each other's adapters.
#pragma once

#include <embree3/rtcore.h>
#include <embree3/rtcore_ray.h>

#include <Eigen/Core>

namespace hp::embree {

/// @brief A single Embree ray from `origin` along `direction` (not
/// necessarily unit: t is in its units) over [tnear, tfar], at time 0,
/// against every geometry (mask all ones), with id and flags 0.
inline RTCRay ray(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float tnear, float tfar) {
    RTCRay r;
    r.org_x = origin.x(), r.org_y = origin.y(), r.org_z = origin.z();
    r.dir_x = direction.x(), r.dir_y = direction.y(), r.dir_z = direction.z();
    r.tnear = tnear;
    r.tfar = tfar;
    r.time = 0.f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    return r;
}

/// @brief The query rtcIntersect1 fills: `ray(...)` and a hit that says "no
/// geometry, no instance" until Embree records one (rtcIntersect1 requires
/// geomID and instID[0] set to RTC_INVALID_GEOMETRY_ID on entry).
inline RTCRayHit rayHit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float tnear, float tfar) {
    RTCRayHit rh;
    rh.ray = ray(origin, direction, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

}  // namespace hp::embree
