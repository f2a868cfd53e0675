// A small 3-vector for the per-contact arithmetic of the DEM kernels. Particle data itself
// lives in structure-of-arrays form (particle_state.h); this type only exists in registers.
#pragma once

#include <cmath>

namespace magbrush::dem {

struct Vector3
{
  double x = 0.0, y = 0.0, z = 0.0;
};

inline Vector3 operator+(const Vector3 &a, const Vector3 &b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vector3 operator-(const Vector3 &a, const Vector3 &b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vector3 operator-(const Vector3 &a) { return {-a.x, -a.y, -a.z}; }
inline Vector3 operator*(double s, const Vector3 &a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vector3 &operator+=(Vector3 &a, const Vector3 &b)
{
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
inline double dot(const Vector3 &a, const Vector3 &b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vector3 cross(const Vector3 &a, const Vector3 &b)
{
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vector3 &a) { return std::sqrt(dot(a, a)); }

} // namespace magbrush::dem
