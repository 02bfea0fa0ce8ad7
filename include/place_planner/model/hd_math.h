// Small vector math usable on the host and in CUDA kernels (one kernel body, two launchers).
// Frames are named in the callers: p_W is a point in frame W, T_WO maps O coordinates to W.
#pragma once
#include <cmath>

#if defined(__CUDACC__)
#define PP_HD __host__ __device__ __forceinline__
#else
#define PP_HD inline
#endif

namespace place_planner {

struct V3 {
  double x, y, z;
};

PP_HD V3 v3(double x, double y, double z) { return V3{x, y, z}; }
PP_HD V3 operator+(V3 a, V3 b) { return V3{a.x + b.x, a.y + b.y, a.z + b.z}; }
PP_HD V3 operator-(V3 a, V3 b) { return V3{a.x - b.x, a.y - b.y, a.z - b.z}; }
PP_HD V3 operator-(V3 a) { return V3{-a.x, -a.y, -a.z}; }
PP_HD V3 operator*(double s, V3 a) { return V3{s * a.x, s * a.y, s * a.z}; }
PP_HD V3 operator*(V3 a, double s) { return V3{s * a.x, s * a.y, s * a.z}; }
PP_HD double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
PP_HD V3 cross(V3 a, V3 b) {
  return V3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
PP_HD double norm2(V3 a) { return dot(a, a); }
PP_HD double norm(V3 a) { return sqrt(dot(a, a)); }
PP_HD V3 normalized(V3 a) {
  const double n = norm(a);
  return n > 0 ? (1.0 / n) * a : a;
}
PP_HD double minv(double a, double b) { return a < b ? a : b; }
PP_HD double maxv(double a, double b) { return a > b ? a : b; }

// Rigid transform p' = R p + t, R row-major.
struct Rigid {
  double R[9];
  V3 t;
};

PP_HD V3 rotate(const Rigid& T, V3 p) {
  return V3{T.R[0] * p.x + T.R[1] * p.y + T.R[2] * p.z, T.R[3] * p.x + T.R[4] * p.y + T.R[5] * p.z,
            T.R[6] * p.x + T.R[7] * p.y + T.R[8] * p.z};
}
PP_HD V3 apply(const Rigid& T, V3 p) { return rotate(T, p) + T.t; }
// Inverse rotation (R^T p).
PP_HD V3 rotateInv(const Rigid& T, V3 p) {
  return V3{T.R[0] * p.x + T.R[3] * p.y + T.R[6] * p.z, T.R[1] * p.x + T.R[4] * p.y + T.R[7] * p.z,
            T.R[2] * p.x + T.R[5] * p.y + T.R[8] * p.z};
}
PP_HD V3 applyInv(const Rigid& T, V3 p) { return rotateInv(T, p - T.t); }

// Rotation of p by angle a about the axis through s with unit direction d (Rodrigues),
// positive angle = counter-clockwise looking against d.
PP_HD V3 rotateAbout(V3 p, V3 s, V3 d, double a) {
  const V3 r = p - s;
  const double c = cos(a), sn = sin(a);
  return s + c * r + sn * cross(d, r) + (1.0 - c) * dot(d, r) * d;
}

}  // namespace place_planner
