#include "place_planner/kernels/transform_vertices.h"

#include "place_planner/infra/parallel_for.h"

namespace place_planner {

void transformVerticesCpu(const Rigid& T_WO, const V3* in, V3* out, size_t n, int threads) {
  parallelFor(n, threads, [&](size_t i) { out[i] = transformVertex(T_WO, in[i]); });
}

}  // namespace place_planner
