// The prepared areas (sphere model, BVHs, height grid: the costly part of a plan) of the last
// few areas, kept by a Planner as a robot places several objects on one area. Frame: the area
// model is in G (scene.h).
#pragma once
#include <Eigen/Core>
#include <memory>
#include <mutex>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/model/scene.h"

namespace place_planner {

// The area's sphere radius for an object sphere radius r: 1.5 r rounded up to a step of a
// factor sqrt(2), so objects of similar sizes share one model (and its grid).
double areaSphereRadius(double object_sphere_radius);

class AreaModelCache {
 public:
  explicit AreaModelCache(size_t capacity = 4) : capacity_(capacity) {}
  // The model of `area_W` for these parameters: from the cache when an entry has the same key
  // and the same mesh and parameters (checked, not only hashed), else built and kept. A mesh
  // over max_triangles is decimated first (work_limits.h; the model says so). `stop` may
  // interrupt the build (Stopped; nothing is kept).
  std::shared_ptr<const AreaModel> get(const Mesh& area_W, const Eigen::Vector3d& gravity_W,
                                       double sphere_radius, double collision_distance,
                                       double grid_cell, size_t max_triangles = static_cast<size_t>(-1),
                                       const StopSignal* stop = nullptr);
  void clear();
  size_t size() const;

 private:
  struct Entry {
    uint64_t key;
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<int, 3>> triangles;
    Eigen::Vector3d gravity;
    double r, cd, cell;
    size_t max_triangles;
    std::shared_ptr<const AreaModel> model;
  };
  size_t capacity_;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // oldest first
  std::shared_ptr<const AreaModel> find(uint64_t key, const Mesh& area, const Eigen::Vector3d& g, double r,
                                        double cd, double cell, size_t max_triangles) const;
};

}  // namespace place_planner
