// Approach, gripper clearance and retreat of a candidate (placeability.h).
#include "place_planner/manipulation/placeability.h"

#include <algorithm>
#include <cmath>

namespace place_planner {
namespace {

// How far the gripper moves from X_GF along dir (unit, G) before it comes nearer the area than
// the clearance, checked every kMotionStep up to `distance`; `distance` when it never does.
double freeSweep(const GripperModel& g, const Eigen::Isometry3d& X_GF, const Eigen::Vector3d& dir,
                 double distance, double clearance, const AreaModel& am) {
  for (double s = kMotionStep; s <= distance + 1e-9; s += kMotionStep) {
    Eigen::Isometry3d X = X_GF;
    X.translation() += s * dir;
    if (gripperClearance(g, X, am, clearance) < clearance) return s - kMotionStep;
  }
  return distance;
}

// min_edge_clearance: rays straight down (G) in 16 directions around the object's footprint,
// each `clearance` beyond the footprint's edge, must meet the area within 1 cm below the
// object's lowest point; a miss or a drop is an edge nearer than that.
bool edgeClear(const ObjectModel& om, const AreaModel& am, const Rigid& X_GO, double clearance) {
  V3 com = apply(X_GO, om.com);
  double zmin = kInf;
  std::vector<V3> v;
  v.reserve(om.vertices.size());
  for (const V3& p : om.vertices) {
    v.push_back(apply(X_GO, p));
    zmin = std::min(zmin, v.back().z);
  }
  const BvhView bvh = view(am.triangle_bvh);
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * M_PI * k / 16;
    const V3 dir = v3(std::cos(a), std::sin(a), 0);
    double reach = 0;
    for (const V3& p : v) reach = std::max(reach, dot(p - com, dir));
    const V3 o = v3(com.x, com.y, 0) + (reach + clearance) * dir + v3(0, 0, zmin + 0.005);
    const V3 down = v3(0, 0, -1);
    const double t = bvhRay(bvh, o, down, 0.015, [&](int i) {
      const auto& f = am.triangles[i];
      return rayTriangle(o, down, am.vertices[f[0]], am.vertices[f[1]], am.vertices[f[2]]);
    });
    if (t > 0.015) return false;
  }
  return true;
}

}  // namespace

bool gripperTiltOk(const Eigen::Matrix3d& R_GO, const PlannerConfig& config) {
  if (!config.has_grasp) return true;
  const Eigen::Vector3d z_F = R_GO * config.grasp.linear().col(2);
  return z_F.dot(-Eigen::Vector3d::UnitZ()) >= std::cos(config.max_gripper_tilt_deg * M_PI / 180.0) - 1e-9;
}

Placement checkPlacement(const TreeLeaf& leaf, const PlaceabilityContext& ctx, const HangingStart* hanging) {
  const PlannerConfig& cfg = ctx.config;
  const Eigen::Matrix3d R_WG = ctx.am.R_GW.transpose();
  const Eigen::Vector3d d = hanging ? hanging->approach : toEigen(ctx.d_vis);
  const double D = hanging ? hanging->approach_distance : cfg.approach_distance;
  Placement out;
  out.checked = true;
  Eigen::Isometry3d goal = toIsometry(leaf.X_GO);
  Eigen::Isometry3d pre = goal;
  Eigen::Isometry3d end = goal;  // where the straight approach ends
  if (hanging) {
    // Threaded along the peg to the first pose of the path (its sweep was checked free by
    // hangingStarts), then lowered onto the peg.
    out.straight = false;
    end = toIsometry(leaf.path.front());
    pre = end;
    pre.translation() -= D * d;
  } else {
    // The object swept straight along d_vis into the goal: free when its first contact (the
    // distance kernel, V-A) is the goal itself (within 0.5 mm).
    pre.translation() -= D * d;
    std::vector<double> t;
    ctx.backend.distance({TranslationQuery{toRigid(pre), ctx.d_vis, D + 0.01}}, t);
    out.straight = t[0] >= D - 1e-3;
    if (!out.straight && leaf.path.size() >= 2) {
      end = toIsometry(leaf.path[1]);  // after the first contact translation: free by construction
      pre = end;
      pre.translation() -= D * d;
    }
  }
  out.approach = LinearMotion{R_WG * d, std::min(cfg.approach_min_distance, D), D, D};
  out.pre_place_W = Eigen::Isometry3d::Identity();
  out.pre_place_W.linear() = R_WG * pre.linear();
  out.pre_place_W.translation() = R_WG * pre.translation();
  // A drop-off around a hanging object is where it hangs, not an edge to keep from.
  if (!hanging && cfg.min_edge_clearance > 0 && !edgeClear(ctx.om, ctx.am, leaf.X_GO, cfg.min_edge_clearance)) {
    out.blocked = "edge";
    return out;
  }
  if (!cfg.gripper || !cfg.has_grasp) return out;

  // The gripper rides with the object: the goal, the poses on the way, the approach.
  const GripperModel& g = *cfg.gripper;
  const double c = cfg.gripper_min_clearance;
  const Eigen::Isometry3d X_OF = cfg.grasp;
  out.gripper_clearance = gripperClearance(g, goal * X_OF, ctx.am, 0.05);
  if (out.gripper_clearance < c) {
    out.blocked = "goal";
    return out;
  }
  for (size_t k = 1; k + 1 < leaf.path.size(); ++k) {
    const double cl = gripperClearance(g, toIsometry(leaf.path[k]) * X_OF, ctx.am, 0.05);
    out.gripper_clearance = std::min(out.gripper_clearance, cl);
    if (cl < c) {
      out.blocked = "intermediate pose";
      return out;
    }
  }
  out.approach.free_distance = freeSweep(g, end * X_OF, -d, D, c, ctx.am);
  if (out.approach.free_distance < cfg.approach_min_distance) {
    out.blocked = "approach";
    return out;
  }
  // Released, the gripper backs off along -z of F.
  const Eigen::Isometry3d X_GF = goal * X_OF;
  const Eigen::Vector3d back = -X_GF.linear().col(2);
  out.retreat = LinearMotion{-Eigen::Vector3d::UnitZ(), cfg.retreat_min_distance, cfg.retreat_distance, 0.0};
  out.retreat.free_distance = freeSweep(g, X_GF, back, cfg.retreat_distance, c, ctx.am);
  if (out.retreat.free_distance < cfg.retreat_min_distance) out.blocked = "retreat";
  return out;
}

}  // namespace place_planner
