#include "place_planner/search/contact_points.h"
#include "place_planner/model/scene.h"

#include <cmath>
#include <map>
#include <tuple>

namespace place_planner {

std::vector<ContactPoint> reduceContacts(const std::vector<SphereContact>& raw, double cell) {
  struct Acc {
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero(), na = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::map<std::tuple<long, long, long>, Acc> voxels;
  for (const auto& c : raw) {
    if (!c.valid) continue;
    const auto key = std::make_tuple(static_cast<long>(std::floor(c.p.x / cell)),
                                     static_cast<long>(std::floor(c.p.y / cell)),
                                     static_cast<long>(std::floor(c.p.z / cell)));
    Acc& a = voxels[key];
    a.p += toEigen(c.p);
    a.n += toEigen(c.n);
    a.na += toEigen(c.na);
    ++a.count;
  }
  std::vector<ContactPoint> out;
  out.reserve(voxels.size());
  for (const auto& kv : voxels) {
    ContactPoint cp;
    cp.p_W = kv.second.p / kv.second.count;
    const double nn = kv.second.n.norm();
    cp.n_W = nn > 0 ? Eigen::Vector3d(kv.second.n / nn) : Eigen::Vector3d::UnitZ();
    const double na = kv.second.na.norm();
    if (na > 1e-9) cp.n_area_W = kv.second.na / na;
    out.push_back(cp);
  }
  return out;
}

std::vector<ContactPoint> reduceContacts(const std::vector<ContactPoint>& contacts, double cell) {
  std::vector<SphereContact> raw;
  raw.reserve(contacts.size());
  for (const auto& c : contacts) raw.push_back(SphereContact{toV3(c.p_W), toV3(c.n_W), 1, toV3(c.n_area_W)});
  return reduceContacts(raw, cell);
}

}  // namespace place_planner
