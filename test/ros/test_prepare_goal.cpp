// prepareGoal (src/node/prepare_goal.cpp) without a node: no roscore, a frame table instead of
// tf2. Every test checks converted values: frames transformed, unset fields -> the parameter,
// 0 -> 0, bad fields -> an error naming them.
// Frames: W = world (planning frame), S = sensor, O = the object's mesh frame, G = gripper.
#include <gtest/gtest.h>
#include <tf2/exceptions.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "place_planner/ros/conversions.h"
#include "place_planner/ros/prepare_goal.h"
#include "place_planner/infra/scenes.h"

namespace place_planner {
namespace {

using Result = PlacePlanResult;

// Mesh messages carry float32 coordinates: a vertex of ~1 m moves by ~1e-7 m through them.
constexpr double kFloat32 = 1e-5;
// Poses composed in double precision.
constexpr double kExact = 1e-9;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Isometry3d X_WS() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translate(Eigen::Vector3d(0.3, -0.2, 0.7));
  X.rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, -0.5).normalized()));
  return X;
}

Eigen::Isometry3d X_WO_start() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translate(Eigen::Vector3d(0.05, 0.02, 0.4));
  X.rotate(Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()));
  return X;
}

// tf2 stand-in: the frames it knows, else what tf2 throws.
FrameLookup frames(int* calls = nullptr) {
  return [calls](const std::string& frame) -> Eigen::Isometry3d {
    if (calls) ++*calls;
    static const std::map<std::string, Eigen::Isometry3d> known{{"sensor", X_WS()}};
    const auto it = known.find(frame);
    if (it == known.end()) throw tf2::LookupException("\"" + frame + "\" passed to lookupTransform does not exist");
    return it->second;
  };
}

Mesh object() { return scenes::box(0.08, 0.06, 0.04); }
Mesh area() { return scenes::plane(0.4, 0.3); }

pcl_msgs::PolygonMesh meshMsg(const Mesh& mesh, const std::string& frame) {
  pcl_msgs::PolygonMesh msg;
  toMsg(mesh, frame, &msg);
  return msg;
}

Mesh mapped(const Mesh& m, const Eigen::Isometry3d& X) { return transformed(m, X.rotation(), X.translation()); }

// Parameters that differ from every value the tests ask for, so "took the parameter" and "took
// the goal's value" cannot be confused.
NodeConfig params() {
  NodeConfig p;
  p.planner.friction = 0.35;
  p.planner.floor_point_spacing = 0.07;
  p.planner.max_rotations = 4;
  p.planner.max_candidates = 7;
  p.planner.min_quality = 0.25;
  p.planner.time_budget_ms = 2000;
  p.verify_top_k = 3;
  return p;
}

PlacePlanGoal goal() {
  PlacePlanGoal g;
  g.object_mesh = meshMsg(object(), "");
  g.placement_area_mesh = meshMsg(area(), "world");
  g.object_pose.header.frame_id = "world";
  toMsg(X_WO_start(), &g.object_pose.pose);
  return g;
}

PreparedGoal prepare(const PlacePlanGoal& g, const NodeConfig& p = params()) {
  return prepareGoal(g, TopicMeshes(), p, frames());
}

// The GoalError prepareGoal throws for g; fails the test when it throws none.
GoalError errorOf(const PlacePlanGoal& g, const TopicMeshes& topics = TopicMeshes()) {
  try {
    prepareGoal(g, topics, params(), frames());
  } catch (const GoalError& e) {
    return e;
  }
  ADD_FAILURE() << "no error";
  return GoalError(Result::SUCCESS, "");
}

bool mentions(const GoalError& e, const std::string& what) {
  return std::string(e.what()).find(what) != std::string::npos;
}

// ---------------------------------------------------------------- frames
TEST(PrepareGoal, MeshesAndPoseInPlanningFrameNeedNoLookup) {
  int calls = 0;
  const PreparedGoal p = prepareGoal(goal(), TopicMeshes(), params(), frames(&calls));
  EXPECT_EQ(calls, 0) << "'' and the planning frame are W itself";
  const Mesh a = area(), o = object();
  ASSERT_EQ(p.area_W.vertices.size(), a.vertices.size());
  ASSERT_EQ(p.object_O.vertices.size(), o.vertices.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) EXPECT_LT((p.area_W.vertices[i] - a.vertices[i]).norm(), kFloat32);
  for (size_t i = 0; i < o.vertices.size(); ++i) EXPECT_LT((p.object_O.vertices[i] - o.vertices[i]).norm(), kFloat32);
  // The held orientation is the start orientation: 0.35 rad about z.
  EXPECT_NEAR(p.config.start_orientation.angularDistance(Eigen::Quaterniond(X_WO_start().rotation())), 0.0, kExact);
  EXPECT_FALSE(p.has_grasp);
}

TEST(PrepareGoal, EverythingInSensorFrameIsBroughtIntoWAndO) {
  const Eigen::Isometry3d X_SW = X_WS().inverse();
  PlacePlanGoal g = goal();
  // The area's vertices in S; the object's vertices in S too, where the object is now.
  g.placement_area_mesh = meshMsg(mapped(area(), X_SW), "sensor");
  g.object_mesh = meshMsg(mapped(object(), X_SW * X_WO_start()), "sensor");
  g.object_pose.header.frame_id = "sensor";
  toMsg(Eigen::Isometry3d(X_SW * X_WO_start()), &g.object_pose.pose);
  const PreparedGoal p = prepare(g);
  // Back in W (area) and O (object): the meshes as built there.
  const Mesh a = area(), o = object();
  ASSERT_EQ(p.area_W.vertices.size(), a.vertices.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    EXPECT_LT((p.area_W.vertices[i] - a.vertices[i]).norm(), kFloat32) << "area vertex " << i;
  }
  ASSERT_EQ(p.object_O.vertices.size(), o.vertices.size());
  for (size_t i = 0; i < o.vertices.size(); ++i) {
    EXPECT_LT((p.object_O.vertices[i] - o.vertices[i]).norm(), kFloat32) << "object vertex " << i;
  }
  // A concrete one: the area's corner (0.2, 0.15, 0) went through X_WS and back.
  EXPECT_NEAR(p.area_W.properties.bounds_max.x(), 0.2, kFloat32);
  EXPECT_NEAR(p.area_W.properties.bounds_max.y(), 0.15, kFloat32);
  EXPECT_NEAR(p.area_W.properties.bounds_max.z(), 0.0, kFloat32);
  EXPECT_NEAR(p.config.start_orientation.angularDistance(Eigen::Quaterniond(X_WO_start().rotation())), 0.0, 1e-6);
}

TEST(PrepareGoal, DirectionsAndRegionAreRotatedIntoW) {
  PlacePlanGoal g = goal();
  // Gravity along -z of S: in W it is R_WS * (0, 0, -1).
  g.gravity.header.frame_id = "sensor";
  g.gravity.vector.z = -2.0;
  g.approach.header.frame_id = "world";
  g.approach.vector.x = 1.0;
  g.approach.vector.z = -1.0;
  // A box of S: W gets the box around its 8 corners.
  g.has_region = true;
  g.region_min.header.frame_id = g.region_max.header.frame_id = "sensor";
  g.region_min.point.x = -0.1, g.region_min.point.y = -0.1, g.region_min.point.z = -0.1;
  g.region_max.point.x = 0.1, g.region_max.point.y = 0.1, g.region_max.point.z = 0.1;
  const PreparedGoal p = prepare(g);
  const Eigen::Vector3d expected_gravity = X_WS().rotation() * Eigen::Vector3d(0, 0, -2.0);
  EXPECT_LT((p.config.gravity - expected_gravity).norm(), kExact);
  EXPECT_LT((p.config.approach - Eigen::Vector3d(1, 0, -1)).norm(), kExact);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d c(k & 1 ? 0.1 : -0.1, k & 2 ? 0.1 : -0.1, k & 4 ? 0.1 : -0.1);
    lo = lo.cwiseMin(X_WS() * c), hi = hi.cwiseMax(X_WS() * c);
  }
  EXPECT_LT((p.config.region_min - lo).norm(), kExact);
  EXPECT_LT((p.config.region_max - hi).norm(), kExact);
  // The box's centre is S's origin, (0.3, -0.2, 0.7) in W.
  EXPECT_LT((0.5 * (p.config.region_min + p.config.region_max) - Eigen::Vector3d(0.3, -0.2, 0.7)).norm(), 1e-9);
  // Zero vectors keep the parameters.
  const PreparedGoal q = prepare(goal());
  EXPECT_EQ(q.config.gravity, params().planner.gravity);
  EXPECT_EQ(q.config.approach, params().planner.approach);
  EXPECT_FALSE(q.config.hasRegion());
}

TEST(PrepareGoal, GraspIsKept) {
  PlacePlanGoal g = goal();
  Eigen::Isometry3d X_OG = Eigen::Isometry3d::Identity();
  X_OG.translate(Eigen::Vector3d(0.01, -0.02, 0.12));
  X_OG.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  g.has_grasp = true;
  toMsg(X_OG, &g.grasp);
  const PreparedGoal p = prepare(g);
  ASSERT_TRUE(p.has_grasp);
  EXPECT_LT((p.X_OG.matrix() - X_OG.matrix()).norm(), 1e-12);
}

// ---------------------------------------------------------------- overrides
TEST(PrepareGoal, DefaultGoalTakesEveryParameter) {
  const PreparedGoal p = prepare(goal());
  const NodeConfig d = params();
  EXPECT_EQ(p.config.friction, 0.35);
  EXPECT_EQ(p.config.floor_point_spacing, 0.07);
  EXPECT_EQ(p.config.max_rotations, 4);
  EXPECT_EQ(p.config.max_candidates, 7);
  EXPECT_EQ(p.config.min_quality, 0.25);
  EXPECT_EQ(p.config.time_budget_ms, 2000.0);
  EXPECT_EQ(p.verify_top_k, 3);
  EXPECT_EQ(p.config.orientation, d.planner.orientation);
}

TEST(PrepareGoal, NanWithoutFlagIsTheParameter) {
  PlacePlanGoal g = goal();
  g.friction = g.floor_point_spacing = g.min_quality = g.time_budget_s = kNaN;
  const PreparedGoal p = prepare(g);
  EXPECT_EQ(p.config.friction, 0.35);
  EXPECT_EQ(p.config.floor_point_spacing, 0.07);
  EXPECT_EQ(p.config.min_quality, 0.25);
  EXPECT_EQ(p.config.time_budget_ms, 2000.0);
}

TEST(PrepareGoal, FlaggedZeroIsReallyZero) {
  PlacePlanGoal g = goal();
  g.use_friction = g.use_max_rotations = g.use_min_quality = g.use_time_budget = g.use_verify_top_k = true;
  g.friction = 0.0;
  g.max_rotations = 0;
  g.min_quality = 0.0;
  g.time_budget_s = 0.0;
  g.verify_top_k = 0;
  const PreparedGoal p = prepare(g);
  EXPECT_EQ(p.config.friction, 0.0);
  EXPECT_EQ(p.config.max_rotations, 0);
  EXPECT_EQ(p.config.min_quality, 0.0);
  EXPECT_EQ(p.config.time_budget_ms, 0.0) << "0 s = no budget";
  EXPECT_EQ(p.verify_top_k, 0);
}

TEST(PrepareGoal, ValuesAreUsedWithOrWithoutFlagAndBudgetIsSeconds) {
  PlacePlanGoal g = goal();
  // Without flags, as older goals set them.
  g.friction = 0.6;
  g.floor_point_spacing = 0.02;
  g.max_rotations = 2;
  g.max_candidates = 30;
  g.min_quality = -0.5;
  g.time_budget_s = 0.25;
  g.verify_top_k = 5;
  g.orientation_mode = "all_axes";
  PreparedGoal p = prepare(g);
  EXPECT_EQ(p.config.friction, 0.6);
  EXPECT_EQ(p.config.floor_point_spacing, 0.02);
  EXPECT_EQ(p.config.max_rotations, 2);
  EXPECT_EQ(p.config.max_candidates, 30);
  EXPECT_EQ(p.config.min_quality, -0.5);
  EXPECT_DOUBLE_EQ(p.config.time_budget_ms, 250.0);
  EXPECT_EQ(p.verify_top_k, 5);
  EXPECT_EQ(p.config.orientation, OrientationMode::kAllAxes);
  // The same with the flags.
  g.use_friction = g.use_floor_point_spacing = g.use_max_rotations = g.use_max_candidates = true;
  g.use_min_quality = g.use_time_budget = g.use_verify_top_k = true;
  p = prepare(g);
  EXPECT_EQ(p.config.friction, 0.6);
  EXPECT_EQ(p.config.max_candidates, 30);
  EXPECT_DOUBLE_EQ(p.config.time_budget_ms, 250.0);
  // A negative verify_top_k is off, with or without the flag.
  g.verify_top_k = -1;
  EXPECT_EQ(prepare(g).verify_top_k, 0);
  g.use_verify_top_k = false;
  EXPECT_EQ(prepare(g).verify_top_k, 0);
}

// ---------------------------------------------------------------- errors
TEST(PrepareGoal, BadFieldIsInvalidGoalNamingIt) {
  struct Case {
    const char* field;
    void (*set)(PlacePlanGoal*);
  };
  const Case cases[] = {
      {"friction", [](PlacePlanGoal* g) { g->friction = -1.0; }},
      {"friction", [](PlacePlanGoal* g) { g->use_friction = true, g->friction = kNaN; }},
      {"floor_point_spacing", [](PlacePlanGoal* g) { g->use_floor_point_spacing = true, g->floor_point_spacing = 0.0; }},
      {"max_rotations", [](PlacePlanGoal* g) { g->max_rotations = 13; }},
      {"max_candidates", [](PlacePlanGoal* g) { g->use_max_candidates = true, g->max_candidates = 0; }},
      {"min_quality", [](PlacePlanGoal* g) { g->min_quality = 1.5; }},
      {"time_budget_s", [](PlacePlanGoal* g) { g->time_budget_s = -0.5; }},
      {"time_budget_s", [](PlacePlanGoal* g) { g->use_time_budget = true, g->time_budget_s = kNaN; }},
      {"verify_top_k", [](PlacePlanGoal* g) { g->verify_top_k = 101; }},
      {"upside_down", [](PlacePlanGoal* g) { g->orientation_mode = "upside_down"; }},
      {"gravity", [](PlacePlanGoal* g) { g->gravity.vector.x = kNaN; }},
      {"object_pose.pose.orientation", [](PlacePlanGoal* g) { g->object_pose.pose.orientation.w = 2.0; }},
      {"grasp", [](PlacePlanGoal* g) { g->has_grasp = true, g->grasp.position.y = kNaN; }},
      {"region_min", [](PlacePlanGoal* g) { g->has_region = true, g->region_min.point.x = 1.0; }},
  };
  for (const Case& c : cases) {
    PlacePlanGoal g = goal();
    c.set(&g);
    const GoalError e = errorOf(g);
    EXPECT_EQ(e.code, Result::INVALID_GOAL) << c.field << ": " << e.what();
    EXPECT_TRUE(mentions(e, c.field)) << c.field << ": " << e.what();
  }
}

TEST(PrepareGoal, UnknownFrameIsTfErrorNamingFieldAndFrame) {
  PlacePlanGoal g = goal();
  g.placement_area_mesh.header.frame_id = "nowhere";
  GoalError e = errorOf(g);
  EXPECT_EQ(e.code, Result::TF_ERROR);
  EXPECT_TRUE(mentions(e, "placement area mesh")) << e.what();
  EXPECT_TRUE(mentions(e, "'nowhere'")) << e.what();
  EXPECT_TRUE(mentions(e, "does not exist")) << "tf2's own reason: " << e.what();
  g = goal();
  g.object_pose.header.frame_id = "gripper_camera";
  e = errorOf(g);
  EXPECT_EQ(e.code, Result::TF_ERROR);
  EXPECT_TRUE(mentions(e, "object_pose")) << e.what();
  EXPECT_TRUE(mentions(e, "'gripper_camera'")) << e.what();
}

TEST(PrepareGoal, BadMeshIsInvalidMeshNamingElement) {
  PlacePlanGoal g = goal();
  // Vertex 5's y: cloud fields x, y, z are float32 at offsets 0, 4, 8.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&g.object_mesh.cloud.data[5 * g.object_mesh.cloud.point_step + 4], &nan, sizeof nan);
  GoalError e = errorOf(g);
  EXPECT_EQ(e.code, Result::INVALID_MESH);
  EXPECT_TRUE(mentions(e, "object mesh")) << e.what();
  EXPECT_TRUE(mentions(e, "vertex 5")) << e.what();
  g = goal();
  g.placement_area_mesh.polygons[0].vertices[0] = 100000;
  e = errorOf(g);
  EXPECT_EQ(e.code, Result::INVALID_MESH);
  EXPECT_TRUE(mentions(e, "placement area mesh")) << e.what();
}

TEST(PrepareGoal, EmptyMeshTakesTheTopicsOrIsNoMesh) {
  PlacePlanGoal g = goal();
  g.placement_area_mesh = pcl_msgs::PolygonMesh();
  TopicMeshes topics;
  topics.area_topic = "/robot/table_mesh";
  GoalError e = errorOf(g, topics);
  EXPECT_EQ(e.code, Result::NO_MESH);
  EXPECT_TRUE(mentions(e, "placement_area_mesh")) << e.what();
  EXPECT_TRUE(mentions(e, "/robot/table_mesh")) << e.what();
  // With a mesh on the topic (a bigger plane, in S) that one is used, brought into W.
  const Mesh big = scenes::plane(1.0, 0.5);
  topics.area = boost::make_shared<pcl_msgs::PolygonMesh>(meshMsg(mapped(big, X_WS().inverse()), "sensor"));
  const PreparedGoal p = prepareGoal(g, topics, params(), frames());
  EXPECT_NEAR(p.area_W.properties.bounds_max.x(), 0.5, kFloat32);
  EXPECT_NEAR(p.area_W.properties.bounds_max.y(), 0.25, kFloat32);
  EXPECT_NEAR(p.area_W.properties.bounds_max.z(), 0.0, kFloat32);
}

// ---------------------------------------------------------------- shape_msgs/Mesh
TEST(ShapeMsgs, MeshConvertsVertexForVertexAndNamesABadIndex) {
  shape_msgs::Mesh m;
  toMsg(object(), &m);
  // A box: 8 vertices, its 6 quads fanned into 12 triangles.
  ASSERT_EQ(m.vertices.size(), 8u);
  ASSERT_EQ(m.triangles.size(), 12u);
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> polygons;
  fromMsg(m, "object shape", &v, &polygons);
  ASSERT_EQ(v.size(), 8u);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], object().vertices[i]);  // float64 kept
  ASSERT_EQ(polygons.size(), 12u);
  for (size_t t = 0; t < polygons.size(); ++t) {
    ASSERT_EQ(polygons[t].size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(polygons[t][k], static_cast<int>(m.triangles[t].vertex_indices[k]));
  }
  EXPECT_NEAR(buildMesh(v, polygons, "object shape").properties.surface_area, object().properties.surface_area, kExact);
  m.triangles[3].vertex_indices[1] = 12;
  try {
    fromMsg(m, "object shape", &v, &polygons);
    ADD_FAILURE() << "index 12 of 8 vertices accepted";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("object shape: triangle 3 has vertex index 12, but the mesh has 8 vertices"),
              std::string::npos) << e.what();
  }
}

TEST(ShapeMsgs, GoalShapesAreUsedWhenThePolygonMeshesAreEmpty) {
  PlacePlanGoal g = goal();
  g.object_mesh = pcl_msgs::PolygonMesh();
  g.placement_area_mesh = pcl_msgs::PolygonMesh();
  toMsg(object(), &g.object_shape);  // frame "" = O
  toMsg(mapped(area(), X_WS().inverse()), &g.placement_area_shape);
  g.placement_area_shape_frame = "sensor";
  const PreparedGoal p = prepare(g);
  ASSERT_EQ(p.object_O.vertices.size(), object().vertices.size());
  for (size_t i = 0; i < p.object_O.vertices.size(); ++i) EXPECT_LT((p.object_O.vertices[i] - object().vertices[i]).norm(), kExact);
  ASSERT_EQ(p.area_W.vertices.size(), area().vertices.size());
  for (size_t i = 0; i < p.area_W.vertices.size(); ++i) EXPECT_LT((p.area_W.vertices[i] - area().vertices[i]).norm(), 1e-12 + 1e-9);
  // A bad index in the goal's shape is INVALID_MESH naming the shape.
  g.placement_area_shape.triangles[1].vertex_indices[0] = 99;
  GoalError e = errorOf(g);
  EXPECT_EQ(e.code, Result::INVALID_MESH);
  EXPECT_TRUE(mentions(e, "placement area shape: triangle 1 has vertex index 99")) << e.what();
  // Neither in the goal nor on a topic: NO_MESH naming both fields and both topics.
  g.placement_area_shape = shape_msgs::Mesh();
  e = errorOf(g);
  EXPECT_EQ(e.code, Result::NO_MESH);
  EXPECT_TRUE(mentions(e, "placement_area_shape")) << e.what();
  EXPECT_TRUE(mentions(e, "placement_area_mesh")) << e.what();
  // The topic's shape, in the frame the parameter names.
  TopicMeshes topics;
  auto shape = boost::make_shared<shape_msgs::Mesh>();
  toMsg(mapped(scenes::plane(1.0, 0.5), X_WS().inverse()), shape.get());
  topics.area_shape = shape;
  NodeConfig np = params();
  np.placement_area_shape_frame = "sensor";
  const PreparedGoal q = prepareGoal(g, topics, np, frames());
  EXPECT_NEAR(q.area_W.properties.bounds_max.x(), 0.5, 1e-9);
  EXPECT_NEAR(q.area_W.properties.bounds_max.y(), 0.25, 1e-9);
}

// ---------------------------------------------------------------- manipulation fields
TEST(PrepareGoal, ManipulationFieldsReachTheConfig) {
  PlacePlanGoal g = goal();
  NodeConfig np = params();
  np.planner.min_edge_clearance = 0.02;
  np.planner.rank_order = RankOrder::kLowest;
  // Unset: the parameters.
  PreparedGoal p = prepare(g, np);
  EXPECT_EQ(p.config.rank_order, RankOrder::kLowest);
  EXPECT_EQ(p.config.min_edge_clearance, 0.02);
  EXPECT_FALSE(p.config.keep_colliding);
  EXPECT_FALSE(p.config.has_grasp);
  // Set: the goal's, prefer_near brought into W, the grasp into the config.
  g.rank_order = "nearest";
  g.prefer_near.header.frame_id = "sensor";
  g.prefer_near.point.x = 0.1;
  g.use_min_edge_clearance = true;
  g.min_edge_clearance = 0.0;
  g.keep_colliding = true;
  g.has_grasp = true;
  Eigen::Isometry3d X_OF = Eigen::Isometry3d::Identity();
  X_OF.translate(Eigen::Vector3d(0, 0, 0.09));
  X_OF.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  toMsg(X_OF, &g.grasp);
  p = prepare(g, np);
  EXPECT_EQ(p.config.rank_order, RankOrder::kNearest);
  EXPECT_LT((p.config.prefer_near - X_WS() * Eigen::Vector3d(0.1, 0, 0)).norm(), kExact);
  EXPECT_EQ(p.config.min_edge_clearance, 0.0);
  EXPECT_TRUE(p.config.keep_colliding);
  EXPECT_TRUE(p.config.has_grasp);
  EXPECT_LT((p.config.grasp.matrix() - X_OF.matrix()).norm(), 1e-12);
  // Bad values name the field.
  g.rank_order = "tallest";
  GoalError e = errorOf(g);
  EXPECT_EQ(e.code, Result::INVALID_GOAL);
  EXPECT_TRUE(mentions(e, "rank_order")) << e.what();
  EXPECT_TRUE(mentions(e, "tallest")) << e.what();
  g.rank_order = "";
  g.min_edge_clearance = -0.01;
  e = errorOf(g);
  EXPECT_EQ(e.code, Result::INVALID_GOAL);
  EXPECT_TRUE(mentions(e, "min_edge_clearance")) << e.what();
}

// ---------------------------------------------------------------- objects one after another
TEST(AreaAdditions, AddMergesThePreviousObjectAtItsCandidateAndResetDropsIt) {
  PlacedObjects placed;
  PlacePlanGoal g = goal();
  int count = -1;
  EXPECT_TRUE(areaAdditions(g, placed, &count).vertices.empty());
  EXPECT_EQ(count, 0);
  // No previous plan: INVALID_GOAL naming add_to_area.
  g.add_to_area = true;
  try {
    areaAdditions(g, placed, &count);
    ADD_FAILURE() << "add_to_area without a previous plan accepted";
  } catch (const GoalError& e) {
    EXPECT_EQ(e.code, Result::INVALID_GOAL);
    EXPECT_TRUE(mentions(e, "add_to_area")) << e.what();
  }
  placed.has_last_plan = true;
  placed.last_object_O = object();
  Eigen::Isometry3d X0 = Eigen::Isometry3d::Identity(), X1 = Eigen::Isometry3d::Identity();
  X0.translation() = Eigen::Vector3d(0.1, 0.05, 0.02);
  X1.translation() = Eigen::Vector3d(-0.1, 0, 0.02);
  X1.rotate(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  placed.last_X_WO = {X0, X1};
  g.add_candidate = 2;
  try {
    areaAdditions(g, placed, &count);
    ADD_FAILURE() << "add_candidate 2 of 2 accepted";
  } catch (const GoalError& e) {
    EXPECT_EQ(e.code, Result::INVALID_GOAL);
    EXPECT_TRUE(mentions(e, "add_candidate = 2 is out of range (the previous plan has 2 candidates: 0 .. 1)")) << e.what();
  }
  g.add_candidate = 1;
  Mesh added = areaAdditions(g, placed, &count);
  EXPECT_EQ(count, 1);
  ASSERT_EQ(added.vertices.size(), 8u);
  for (size_t i = 0; i < 8; ++i) EXPECT_LT((added.vertices[i] - X1 * object().vertices[i]).norm(), kExact);
  // A second one is merged beside the first.
  placed.added_W = added;
  placed.count = 1;
  g.add_candidate = 0;
  added = areaAdditions(g, placed, &count);
  EXPECT_EQ(count, 2);
  EXPECT_EQ(added.vertices.size(), 16u);
  EXPECT_NEAR(added.properties.surface_area, 2 * object().properties.surface_area, 1e-9);
  // reset_area first: only the new one.
  g.reset_area = true;
  added = areaAdditions(g, placed, &count);
  EXPECT_EQ(count, 1);
  EXPECT_EQ(added.vertices.size(), 8u);
  g.add_to_area = false;
  EXPECT_TRUE(areaAdditions(g, placed, &count).vertices.empty());
  EXPECT_EQ(count, 0);
  // prepareGoal merges them into the area.
  g.reset_area = false;
  const PreparedGoal p = prepareGoal(goal(), TopicMeshes(), params(), frames(), &placed.added_W);
  EXPECT_EQ(p.area_W.vertices.size(), area().vertices.size() + 8);
  EXPECT_NEAR(p.area_W.properties.bounds_max.z(), 0.04, kFloat32);
}

TEST(ErrorCodeName, NamesEveryCode) {
  EXPECT_STREQ(errorCodeName(Result::SUCCESS), "SUCCESS");
  EXPECT_STREQ(errorCodeName(Result::PREEMPTED), "PREEMPTED");
  EXPECT_STREQ(errorCodeName(Result::INTERNAL_ERROR), "INTERNAL_ERROR");
  EXPECT_STREQ(errorCodeName(200), "UNKNOWN");
}

}  // namespace
}  // namespace place_planner

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
