// Per-element body of the vertex transform, shared by the CPU and CUDA launchers.
#pragma once
#include <cstddef>
#include <vector>

#include "place_planner/model/hd_math.h"

namespace place_planner {

PP_HD V3 transformVertex(const Rigid& T_WO, V3 p_O) { return apply(T_WO, p_O); }

// CPU launcher (threads): out[i] = T_WO * in[i].
void transformVerticesCpu(const Rigid& T_WO, const V3* in, V3* out, size_t n, int threads = 0);

}  // namespace place_planner
