// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/render/room_scene.h>

#include <lumx/core/diagnostic.h>

#include <embree3/rtcore.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace render {

struct RoomScene::Impl {
  Room room;
  std::vector<RoomSurface> surfaces;
  std::vector<float> vertices;          // 4 per surface, xyz (+1 float of padding for Embree's SSE loads)
  std::vector<unsigned> indices;        // 2 triangles per surface
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RoomScene::RoomScene(const Room& room) : impl_(std::make_unique<Impl>()) {
  if (const std::string why = invalid_reason(room); !why.empty()) {
    Diagnostic d;
    d.file = "room";
    d.field = "room";
    d.message = why;
    throw Error(d);
  }
  Impl& m = *impl_;
  m.room = room;
  m.surfaces = room_surfaces(room);
  for (std::size_t s = 0; s < m.surfaces.size(); ++s) {
    const RoomSurface& f = m.surfaces[s];
    const glm::dvec3 corners[4] = {f.point(0, 0), f.point(f.width_m, 0), f.point(f.width_m, f.height_m),
                                   f.point(0, f.height_m)};
    for (const glm::dvec3& c : corners) {
      m.vertices.push_back(float(c.x));
      m.vertices.push_back(float(c.y));
      m.vertices.push_back(float(c.z));
    }
    const unsigned b = unsigned(4 * s);
    for (unsigned i : {b, b + 1, b + 2, b, b + 2, b + 3}) m.indices.push_back(i);
  }
  m.vertices.push_back(0.0f);
  m.device = rtcNewDevice(nullptr);
  if (!m.device) throw std::runtime_error("Embree: rtcNewDevice failed");
  m.scene = rtcNewScene(m.device);
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geom = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.vertices.data(), 0,
                             3 * sizeof(float), m.surfaces.size() * 4);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.indices.data(), 0,
                             3 * sizeof(unsigned), m.surfaces.size() * 2);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(m.scene, geom, 0);
  rtcReleaseGeometry(geom);
  rtcCommitScene(m.scene);
}

RoomScene::~RoomScene() = default;

const Room& RoomScene::room() const { return impl_->room; }
const std::vector<RoomSurface>& RoomScene::surfaces() const { return impl_->surfaces; }

RoomHit RoomScene::intersect(const glm::dvec3& origin, const glm::dvec3& direction, double max_distance) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = float(origin.x);
  rh.ray.org_y = float(origin.y);
  rh.ray.org_z = float(origin.z);
  rh.ray.dir_x = float(direction.x);
  rh.ray.dir_y = float(direction.y);
  rh.ray.dir_z = float(direction.z);
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = float(std::min(max_distance, 1e30));
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  RoomHit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.surface = int(rh.hit.primID / 2);
  const RoomSurface& f = impl_->surfaces[std::size_t(hit.surface)];
  hit.distance_m = double(rh.ray.tfar);
  hit.point = origin + hit.distance_m * direction;
  const glm::dvec2 uv = f.uv(hit.point);
  hit.u = std::clamp(uv.x, 0.0, f.width_m);
  hit.v = std::clamp(uv.y, 0.0, f.height_m);
  hit.point = f.point(hit.u, hit.v);  // exactly on the plane (float hits are off by ~1e-7 m)
  hit.front = glm::dot(direction, f.normal) < 0.0;
  return hit;
}

bool RoomScene::visible(const glm::dvec3& from, const glm::dvec3& to) const {
  const glm::dvec3 d = to - from;
  const double length = glm::length(d);
  if (!(length > 0.0)) return true;
  const double eps = 1e-5 * length + 1e-6;
  if (length <= 2.0 * eps) return true;
  const glm::dvec3 w = d / length;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = float(from.x);
  ray.org_y = float(from.y);
  ray.org_z = float(from.z);
  ray.dir_x = float(w.x);
  ray.dir_y = float(w.y);
  ray.dir_z = float(w.z);
  ray.tnear = float(eps);
  ray.tfar = float(length - eps);
  ray.mask = 0xFFFFFFFFu;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar >= 0.0f;  // Embree sets tfar to −inf when occluded
}

}  // namespace render
LUMX_NAMESPACE_END
