#include "cuda_common.cuh"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/kernels/transform_vertices.h"

namespace place_planner {
namespace cuda {

__global__ void transformVerticesKernel(Rigid T, const V3* in, V3* out, size_t n) {
  for (size_t i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x)
    out[i] = transformVertex(T, in[i]);
}

void transformVertices(const Rigid& T, const V3* in, V3* out, size_t n) {
  if (n == 0) return;
  DeviceBuffer<V3> d_in(n), d_out(n);
  d_in.upload(in);
  transformVerticesKernel<<<blocksFor(n), 256>>>(T, d_in.get(), d_out.get(), n);
  PP_CUDA_CHECK(cudaGetLastError());
  PP_CUDA_CHECK(cudaDeviceSynchronize());
  d_out.download(out);
}

}  // namespace cuda
}  // namespace place_planner
