// Cache of prepared areas (area_model_cache.h).
#include "place_planner/model/area_model_cache.h"

#include <cmath>
#include <cstring>

#include "place_planner/infra/work_limits.h"

namespace place_planner {
namespace {

// FNV-1a over the 64-bit words of the area mesh and the model parameters (a key only: entries
// are compared in full).
uint64_t fingerprint(const Mesh& area, const Eigen::Vector3d& g, double r, double cd, double cell) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, size_t n) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i + 8 <= n; i += 8) {
      uint64_t w;
      std::memcpy(&w, b + i, 8);
      h = (h ^ w) * 1099511628211ull;
    }
    for (size_t i = n - n % 8; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  for (const auto& v : area.vertices) mix(v.data(), 3 * sizeof(double));
  for (const auto& t : area.triangles) mix(t.data(), 3 * sizeof(int));
  const double p[6] = {g.x(), g.y(), g.z(), r, cd, cell};
  mix(p, sizeof p);
  return h;
}

}  // namespace

double areaSphereRadius(double r) {
  const double step = std::sqrt(2.0);
  const double base = 0.001;  // 1 mm, steps of sqrt(2) from there
  const double k = std::ceil(std::log(1.5 * r / base) / std::log(step) - 1e-9);
  return base * std::pow(step, k);
}

std::shared_ptr<const AreaModel> AreaModelCache::find(uint64_t key, const Mesh& area, const Eigen::Vector3d& g,
                                                      double r, double cd, double cell,
                                                      size_t max_triangles) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Entry& e : entries_)
    if (e.key == key && e.r == r && e.cd == cd && e.cell == cell && e.gravity == g &&
        e.max_triangles == max_triangles && e.vertices == area.vertices && e.triangles == area.triangles)
      return e.model;
  return nullptr;
}

std::shared_ptr<const AreaModel> AreaModelCache::get(const Mesh& area, const Eigen::Vector3d& g,
                                                     double r, double cd, double cell, size_t max_triangles,
                                                     const StopSignal* stop) {
  const uint64_t key = fingerprint(area, g, r, cd, cell);
  if (auto hit = find(key, area, g, r, cd, cell, max_triangles)) return hit;
  std::shared_ptr<AreaModel> model;
  if (area.triangles.size() > max_triangles) {
    double h = 0;
    const Mesh small = decimated(area, max_triangles, &h, stop);
    model = std::make_shared<AreaModel>(buildAreaModel(small, g, r, cd, cell, stop));
    model->decimation_cell = h;
  } else {
    model = std::make_shared<AreaModel>(buildAreaModel(area, g, r, cd, cell, stop));
  }
  model->source_triangles = area.triangles.size();
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.push_back(Entry{key, area.vertices, area.triangles, g, r, cd, cell, max_triangles, model});
  if (entries_.size() > capacity_) entries_.erase(entries_.begin());
  return model;
}

void AreaModelCache::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
}

size_t AreaModelCache::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

}  // namespace place_planner
