// The batched steps of the planner (Section VII-C): each call processes every pending pose
// that needs that step at once. The CPU backend runs the per-pose kernels of
// kernels/placement_kernels.h on threads; the CUDA backend runs the same kernels on the GPU.
// Results must not depend on the backend or the thread count beyond floating-point rounding.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "place_planner/kernels/placement_kernels.h"
#include "place_planner/model/scene.h"

namespace place_planner {

struct TranslationQuery {
  Rigid X_GO;
  V3 d;         // unit direction, frame G
  double tmax;  // search limit, m
};

struct RotationQuery {
  Rigid X_GO;
  V3 s_A, d_A;  // axis point and unit direction, frame G
  // Angles at or beyond these are not needed (a contact was already found there by the other
  // rotation kernel): the search stops early.
  double limit_ccw = kInf, limit_cw = kInf;
};

struct AnglePair {
  double ccw = kInf;  // smallest positive rotation about +d_A to a new contact
  double cw = kInf;   // ... about -d_A
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  // Poses the planner should batch per step: the CPU a few per thread, a GPU every pending
  // pose of every root (as many as its memory for the contact kernel allows).
  virtual size_t preferredBatch() const = 0;
  // Distance kernel: t per query (kInf: no contact within tmax).
  virtual void distance(const std::vector<TranslationQuery>& q, std::vector<double>& t) = 0;
  // Vertex/surface and edge/edge rotation kernels.
  virtual void vertexSurfaceRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) = 0;
  virtual void edgeEdgeRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) = 0;
  // Contact point kernel: per pose, the contacts of every object sphere that touches the area
  // (in sphere order).
  virtual void contactPoints(const std::vector<Rigid>& X_GO,
                             std::vector<std::vector<SphereContact>>& c) = 0;
};

// Views of the host models (pointers into them: the models must outlive the views).
ObjectView view(const ObjectModel& o);
AreaView view(const AreaModel& a);

std::unique_ptr<Backend> makeCpuBackend(const ObjectModel& object, const AreaModel& area,
                                        const TiltParams& tilt, int threads);
// Throws std::runtime_error when CUDA is not built in, no GPU answers or the device was
// marked unusable by an earlier fault (cuda_backend.h).
std::unique_ptr<Backend> makeCudaBackend(const ObjectModel& object, const AreaModel& area,
                                         const TiltParams& tilt);

}  // namespace place_planner
