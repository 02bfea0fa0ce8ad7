// Per-element geometry of the planner, __host__ __device__, shared by the CPU backend and the
// CUDA kernels (one body, two launchers). Frames: every argument is in the same frame G (the
// planning frame rotated so that gravity is -z); angles are counter-clockwise about the unit
// axis direction d_A (right-hand rule), in [0, 2*pi).
#pragma once
#include "place_planner/model/hd_math.h"

namespace place_planner {

// Relative tolerance of the closed forms below; geometry is in metres at object scale.
constexpr double kGeomEps = 1e-12;
constexpr double kTwoPi = 6.283185307179586;
constexpr double kInf = 1e300;

struct Aabb {
  V3 lo, hi;
};

PP_HD Aabb aabbEmpty() { return Aabb{v3(kInf, kInf, kInf), v3(-kInf, -kInf, -kInf)}; }
PP_HD void aabbAdd(Aabb& b, V3 p) {
  b.lo = v3(minv(b.lo.x, p.x), minv(b.lo.y, p.y), minv(b.lo.z, p.z));
  b.hi = v3(maxv(b.hi.x, p.x), maxv(b.hi.y, p.y), maxv(b.hi.z, p.z));
}
PP_HD void aabbMerge(Aabb& b, const Aabb& o) {
  aabbAdd(b, o.lo);
  aabbAdd(b, o.hi);
}
PP_HD Aabb aabbInflate(Aabb b, double r) {
  return Aabb{b.lo - v3(r, r, r), b.hi + v3(r, r, r)};
}
PP_HD bool aabbOverlap(const Aabb& a, const Aabb& b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
         a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}

// Normalises an angle to [0, 2 pi).
PP_HD double wrapAngle(double a) {
  a = fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

// ---------------------------------------------------------------------- translation (V-A)

// Distance t >= 0 along unit d at which the ray o + t d meets triangle (a, b, c), both sides
// (Moeller-Trumbore); kInf when it misses. Rays in the triangle's plane miss.
PP_HD double rayTriangle(V3 o, V3 d, V3 a, V3 b, V3 c) {
  const V3 e1 = b - a, e2 = c - a;
  const V3 p = cross(d, e2);
  const double det = dot(e1, p);
  const double scale = norm2(e1) * norm2(e2);
  if (det * det <= kGeomEps * kGeomEps * scale) return kInf;
  const double inv = 1.0 / det;
  const V3 s = o - a;
  const double u = dot(s, p) * inv;
  if (u < -1e-9 || u > 1 + 1e-9) return kInf;
  const V3 q = cross(s, e1);
  const double v = dot(d, q) * inv;
  if (v < -1e-9 || u + v > 1 + 1e-9) return kInf;
  const double t = dot(e2, q) * inv;
  return t >= 0 ? t : kInf;
}

// Distance t >= 0 along unit d that brings the moving segment p0p1 into contact with the fixed
// segment q0q1 (edge/edge case of the translation): solves p0 + s (p1 - p0) + t d =
// q0 + u (q1 - q0) for s, u in [0, 1]. kInf when they never meet or the segments are parallel
// to each other or to d (then vertex/face tests find the contact).
PP_HD double edgeEdgeTranslation(V3 p0, V3 p1, V3 q0, V3 q1, V3 d) {
  const V3 ep = p1 - p0, eq = q1 - q0;
  // Dot with n = ep x eq removes s and u: t = n.(q0 - p0) / n.d.
  const V3 n = cross(ep, eq);
  const double nd = dot(n, d);
  if (fabs(nd) <= 1e-9 * norm(ep) * norm(eq)) return kInf;
  const V3 r = q0 - p0;
  const double t = dot(r, n) / nd;
  if (t < 0) return kInf;
  // In the plane of ep, eq: s ep - u eq = r - t d.
  const V3 pr = r - t * d;
  const double ee = dot(ep, ep), eqq = dot(eq, eq), epq = dot(ep, eq);
  const double den = ee * eqq - epq * epq;
  if (fabs(den) <= kGeomEps * ee * eqq) return kInf;
  const double a1 = dot(pr, ep), a2 = dot(pr, eq);
  const double s = (a1 * eqq - a2 * epq) / den;
  const double u = (a1 * epq - a2 * ee) / den;
  if (s < -1e-9 || s > 1 + 1e-9 || u < -1e-9 || u > 1 + 1e-9) return kInf;
  return t;
}

// ---------------------------------------------------------------------- rotation (V-C.2)

// Point-in-triangle for a point already on the triangle's plane (barycentric, with tolerance).
PP_HD bool insideTriangle(V3 p, V3 a, V3 b, V3 c, double tol) {
  const V3 n = cross(b - a, c - a);
  const double nn = norm(n);
  if (nn <= 0) return false;
  const V3 nu = (1.0 / nn) * n;
  // Signed distances of p from each edge, inside the triangle plane.
  const double d0 = dot(cross(b - a, p - a), nu) / norm(b - a);
  const double d1 = dot(cross(c - b, p - b), nu) / norm(c - b);
  const double d2 = dot(cross(a - c, p - c), nu) / norm(a - c);
  return d0 >= -tol && d1 >= -tol && d2 >= -tol;
}

// Vertex/polygon rotational contact (V-C.2a): the circle D(v, A) of vertex v about the axis
// A = s_A + lambda d_A, intersected with the plane P(S) of triangle S = (a, b, c); the points
// inside S give the rotation angles. Writes up to 2 angles in [0, 2 pi) to out; returns count.
// A vertex on the axis (radius 0) never moves: 0 angles. Tangent circles give one angle.
PP_HD int vertexTriangleAngles(V3 v, V3 s_A, V3 d_A, V3 a, V3 b, V3 c, double tol, double out[2]) {
  const V3 c0 = s_A + dot(v - s_A, d_A) * d_A;  // circle centre
  const V3 r = v - c0;
  const double rho = norm(r);
  if (rho <= 1e-12) return 0;
  const V3 e1 = (1.0 / rho) * r;
  const V3 e2 = cross(d_A, e1);
  V3 n = cross(b - a, c - a);
  const double nn = norm(n);
  if (nn <= 0) return 0;
  n = (1.0 / nn) * n;
  // n.(c0 - a) + rho (cos t n.e1 + sin t n.e2) = 0  <=>  A cos t + B sin t = -D
  const double A = rho * dot(n, e1), B = rho * dot(n, e2), D = dot(n, c0 - a);
  const double R = sqrt(A * A + B * B);
  if (R <= 1e-15 || fabs(D) > R) return 0;
  const double phi = atan2(B, A);
  const double delta = acos(minv(1.0, maxv(-1.0, -D / R)));
  int k = 0;
  for (int s = 0; s < 2; ++s) {
    const double t = wrapAngle(phi + (s == 0 ? delta : -delta));
    if (s == 1 && delta < 1e-12) break;  // tangent: one point
    const V3 p = c0 + rho * cos(t) * e1 + rho * sin(t) * e2;
    if (insideTriangle(p, a, b, c, tol)) out[k++] = t;
  }
  return k;
}

// Surface of revolution swept by a segment about the z axis (Table I): x^2 + y^2 = q(z) with
// q(z) = qa z^2 + qb z + qc over the segment's z range; an annulus when the segment is
// horizontal. kind: 0 annulus, 1 cylinder, 2 cone, 3 one-sheet hyperboloid.
struct Revolution {
  int kind;
  double qa, qb, qc;  // unused for the annulus
  double z0, z1;      // z range of the generatrix
};

PP_HD Revolution revolutionOf(V3 p0, V3 p1) {
  Revolution h;
  const V3 d = p1 - p0;
  h.z0 = minv(p0.z, p1.z);
  h.z1 = maxv(p0.z, p1.z);
  const double len = norm(d);
  if (fabs(d.z) <= 1e-12 * (len + 1e-300)) {
    h.kind = 0;
    h.qa = h.qb = h.qc = 0;
    return h;
  }
  // p(z) = p0 + (z - p0.z)/d.z * d: x(z) = x0 + kx (z - z_p0), y likewise.
  const double kx = d.x / d.z, ky = d.y / d.z;
  const double bx = p0.x - kx * p0.z, by = p0.y - ky * p0.z;
  h.qa = kx * kx + ky * ky;
  h.qb = 2 * (kx * bx + ky * by);
  h.qc = bx * bx + by * by;
  // Cylinder: generatrix parallel to the axis; cone: its line meets the axis (min radius 0);
  // otherwise a hyperboloid of one sheet whose waist is the line's closest point to the axis.
  const double dxy2 = d.x * d.x + d.y * d.y;
  if (dxy2 <= 1e-24 * len * len) {
    h.kind = 1;
  } else {
    const double min_r2 = h.qc - h.qb * h.qb / (4 * h.qa);
    h.kind = min_r2 <= 1e-18 * (h.qc + 1e-300) ? 2 : 3;
  }
  return h;
}

// Edge/edge rotational contact (V-C.2b). Segment p0p1 rotates about the axis (s_A, d_A);
// q0q1 is fixed. Transforms both so that A is the z axis (step 2), builds the surface of
// revolution of the rotating segment (step 3), intersects the fixed segment with it and
// measures the angle from the rotating segment's point at that height to the hit (step 4).
// Writes up to 4 angles in [0, 2 pi); returns count.
PP_HD int edgeEdgeAnglesAxis(V3 P0, V3 P1, V3 Q0, V3 Q1, double out[4]);
// Axis frame of (s_A, d_A): origin s_A, z = d_A (step 2 of V-C.2b).
struct AxisFrame {
  V3 o, ex, ey, ez;
};
PP_HD AxisFrame axisFrame(V3 s_A, V3 d_A) {
  const V3 ref = fabs(d_A.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
  const V3 ex = normalized(cross(ref, d_A));
  return AxisFrame{s_A, ex, cross(d_A, ex), d_A};
}
PP_HD V3 toAxis(const AxisFrame& f, V3 p) {
  const V3 r = p - f.o;
  return v3(dot(r, f.ex), dot(r, f.ey), dot(r, f.ez));
}

// Edge/edge rotational contact in the axis frame (rotation about +z through the origin):
// P0P1 rotates, Q0Q1 is fixed. See edgeEdgeAngles.
PP_HD int edgeEdgeAnglesAxis(V3 P0, V3 P1, V3 Q0, V3 Q1, double out[4]) {
  // (1) Pretest: the z ranges must overlap, and the radius ranges too.
  const double pz0 = minv(P0.z, P1.z), pz1 = maxv(P0.z, P1.z);
  const double qz0 = minv(Q0.z, Q1.z), qz1 = maxv(Q0.z, Q1.z);
  if (qz1 < pz0 - 1e-12 || qz0 > pz1 + 1e-12) return 0;
  const Revolution H = revolutionOf(P0, P1);
  const V3 dq = Q1 - Q0;
  // r^2(u) of the fixed segment: |Q0xy + u dqxy|^2 = A2 u^2 + A1 u + A0.
  const double A2 = dq.x * dq.x + dq.y * dq.y, A1 = 2 * (Q0.x * dq.x + Q0.y * dq.y),
               A0 = Q0.x * Q0.x + Q0.y * Q0.y;
  double us[2];
  int nu = 0;
  if (H.kind == 0) {
    // Annulus at height P0.z: the fixed segment must cross that height.
    if (fabs(dq.z) <= 1e-15) return 0;  // coplanar horizontal segments: handled by vertex tests
    const double u = (P0.z - Q0.z) / dq.z;
    if (u < -1e-9 || u > 1 + 1e-9) return 0;
    us[nu++] = u;
  } else {
    // z(u) = Q0.z + u dq.z; q(z(u)) = qa z^2 + qb z + qc; solve r^2(u) = q(z(u)).
    const double z0 = Q0.z, z1 = dq.z;
    const double c2 = A2 - H.qa * z1 * z1;
    const double c1 = A1 - (2 * H.qa * z0 * z1 + H.qb * z1);
    const double c0 = A0 - (H.qa * z0 * z0 + H.qb * z0 + H.qc);
    const double sc = fabs(c2) + fabs(c1) + fabs(c0);
    if (fabs(c2) <= 1e-12 * sc) {
      if (fabs(c1) <= 1e-12 * sc) return 0;  // the segment lies on H: no isolated contact
      us[nu++] = -c0 / c1;
    } else {
      const double disc = c1 * c1 - 4 * c2 * c0;
      if (disc < 0) return 0;
      const double sq = sqrt(disc);
      // Numerically stable roots.
      const double qq = -0.5 * (c1 + (c1 >= 0 ? sq : -sq));
      us[nu++] = qq / c2;
      if (qq != 0) us[nu++] = c0 / qq;
    }
  }
  int k = 0;
  const V3 dp = P1 - P0;
  for (int i = 0; i < nu; ++i) {
    const double u = us[i];
    if (u < -1e-9 || u > 1 + 1e-9) continue;
    const V3 q = Q0 + u * dq;
    const double rq2 = q.x * q.x + q.y * q.y;
    // Points of the rotating segment at the hit's height with the hit's radius.
    double ss[2];
    int ns = 0;
    if (H.kind != 0) {
      ss[ns++] = (q.z - P0.z) / dp.z;
    } else {
      // Annulus: |P0xy + s dpxy|^2 = rq2.
      const double b2 = dp.x * dp.x + dp.y * dp.y, b1 = 2 * (P0.x * dp.x + P0.y * dp.y),
                   b0 = P0.x * P0.x + P0.y * P0.y - rq2;
      if (b2 <= 1e-24) continue;
      const double disc = b1 * b1 - 4 * b2 * b0;
      if (disc < 0) continue;
      const double sq = sqrt(disc);
      ss[ns++] = (-b1 + sq) / (2 * b2);
      if (sq > 0) ss[ns++] = (-b1 - sq) / (2 * b2);
    }
    for (int j = 0; j < ns && k < 4; ++j) {
      const double s = ss[j];
      if (s < -1e-9 || s > 1 + 1e-9) continue;
      const V3 p = P0 + s * dp;
      const double rp2 = p.x * p.x + p.y * p.y;
      if (rp2 <= 1e-20 || fabs(rp2 - rq2) > 1e-9 * (rp2 + rq2) + 1e-16) continue;
      // Angle alpha from p to q about z (Fig. 4).
      const double a = atan2(p.x * q.y - p.y * q.x, p.x * q.x + p.y * q.y);
      out[k++] = wrapAngle(a);
    }
  }
  return k;
}

PP_HD int edgeEdgeAngles(V3 p0, V3 p1, V3 q0, V3 q1, V3 s_A, V3 d_A, double out[4]) {
  const AxisFrame f = axisFrame(s_A, d_A);
  return edgeEdgeAnglesAxis(toAxis(f, p0), toAxis(f, p1), toAxis(f, q0), toAxis(f, q1), out);
}

// Conservative bounding box of the arc swept by p rotating about (s_A, d_A) through angles
// [a0, a1] (a1 - a0 <= pi/2 keeps it tight): the chord end points and the arc midpoint pushed
// out to the tangent intersection.
// Rotation about (s, d) by the angle whose cosine and sine are c, sn.
PP_HD V3 rotateAboutCS(V3 p, V3 s, V3 d, double c, double sn) {
  const V3 r = p - s;
  return s + c * r + sn * cross(d, r) + (1.0 - c) * dot(d, r) * d;
}

// An angle window [a0, a1] with its sines and cosines, for arcBoxW.
struct AngleWindow {
  double c0, s0, c1, s1, cm, sm, inv_cos_half;
};
PP_HD AngleWindow angleWindow(double a0, double a1) {
  const double m = 0.5 * (a0 + a1);
  return AngleWindow{cos(a0), sin(a0), cos(a1), sin(a1), cos(m), sin(m),
                     1.0 / maxv(cos(0.5 * fabs(a1 - a0)), 1e-3)};
}
PP_HD Aabb arcBoxW(V3 p, V3 s_A, V3 d_A, const AngleWindow& w) {
  // p = c + u rotates to c + cos(a) u + sin(a) (d x u): the circle's centre c and radial u once.
  const V3 r = p - s_A;
  const V3 c = s_A + dot(r, d_A) * d_A;
  const V3 u = p - c, t = cross(d_A, r);
  Aabb b = aabbEmpty();
  aabbAdd(b, c + w.c0 * u + w.s0 * t);
  aabbAdd(b, c + w.c1 * u + w.s1 * t);
  aabbAdd(b, c + (w.inv_cos_half * w.cm) * u + (w.inv_cos_half * w.sm) * t);
  return b;
}

PP_HD Aabb arcBox(V3 p, V3 s_A, V3 d_A, double a0, double a1) {
  Aabb b = aabbEmpty();
  const V3 pa = rotateAbout(p, s_A, d_A, a0);
  const V3 pb = rotateAbout(p, s_A, d_A, a1);
  aabbAdd(b, pa);
  aabbAdd(b, pb);
  const double half = 0.5 * (a1 - a0);
  const V3 pm = rotateAbout(p, s_A, d_A, a0 + half);
  const V3 c0 = s_A + dot(p - s_A, d_A) * d_A;
  const double cs = cos(half);
  aabbAdd(b, c0 + (1.0 / maxv(cs, 1e-3)) * (pm - c0));
  return b;
}

}  // namespace place_planner
