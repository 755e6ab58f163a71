#include "kernels/common/strand_kernels.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairbench::kernels {

namespace {
Vec3f xyz(const Vec4f& v) { return v.head<3>(); }
}  // namespace

void follow_head(std::span<Vec4f> pos, std::span<Vec4f> prev, std::span<const Vec4f> rest,
                 const Affine3f& head) {
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (rest[i].w() != 0.0f) continue;
    prev[i] = pos[i];
    pos[i].head<3>() = head * xyz(rest[i]);
  }
}

void follow_head_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec4f> rest,
                       const Affine3f& head) {
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (rest[i].w() != 0.0f) continue;
    const Vec3f old = xyz(pos[i]);
    pos[i].head<3>() = head * xyz(rest[i]);
    step[i].head<3>() = xyz(pos[i]) - old;
  }
}

namespace {
// verlet_integrate's loop; kSteps: `state` holds each vertex's last step (p - p_prev),
// else its previous position.
template <bool kSteps>
void verlet(std::span<Vec4f> pos, std::span<Vec4f> state, const Vec3f& gravity, const Wind& wind,
            bool wind_term, float damping, float dt) {
  const float keep = 1.0f - damping;
  const float dt2 = dt * dt;
  const Vec3f wind_acc = wind.acceleration();
  for (std::size_t i = 1; i < pos.size(); ++i) {
    if (pos[i].w() == 0.0f) continue;
    Vec3f acc = gravity;
    if (wind_term) {
      const Vec3f edge = xyz(pos[i]) - xyz(pos[i - 1]);
      const float len2 = edge.squaredNorm();
      const Vec3f t = len2 > 0.0f ? Vec3f(edge / std::sqrt(len2)) : Vec3f::Zero();
      acc += wind_acc - wind_acc.dot(t) * t;
    }
    const Vec3f p = xyz(pos[i]);
    if constexpr (kSteps) {
      const Vec3f s = keep * xyz(state[i]) + acc * dt2;
      state[i].head<3>() = s;
      pos[i].head<3>() = p + s;
    } else {
      pos[i].head<3>() = p + keep * (p - xyz(state[i])) + acc * dt2;
      state[i].head<3>() = p;
    }
  }
}

// edge_length's sweep; a non-empty `step` takes every correction too.
void edge_sweep(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const float> rest_length) {
  const std::size_t n = pos.size();
  const bool steps = !step.empty();
  for (std::size_t first : {std::size_t{1}, std::size_t{2}})
    for (std::size_t i = first; i < n; i += 2) {
      Vec4f& a = pos[i - 1];
      Vec4f& b = pos[i];
      const float wsum = a.w() + b.w();
      if (wsum == 0.0f) continue;
      const Vec3f d = xyz(b) - xyz(a);
      const float len = d.norm();
      if (!(len > 0.0f)) continue;
      const Vec3f corr = d * ((len - rest_length[i]) / (len * wsum));
      a.head<3>() += a.w() * corr;
      b.head<3>() -= b.w() * corr;
      if (steps) {
        step[i - 1].head<3>() += a.w() * corr;
        step[i].head<3>() -= b.w() * corr;
      }
    }
}

// collide_spheres for one free vertex; whether it was inside a sphere.
bool push_out(Vec4f& p, std::span<const Vec4f> world_spheres) {
  constexpr int kPasses = 4;
  bool inside = false;
  for (int pass = 0; pass < kPasses; ++pass) {
    bool moved = false;
    for (const Vec4f& s : world_spheres) {
      const Vec3f d = xyz(p) - xyz(s);
      const float r = s.w();
      const float dist2 = d.squaredNorm();
      if (dist2 >= r * r) continue;
      const float dist = std::sqrt(dist2);
      // A vertex exactly at the centre has no closest point; push it straight up.
      const Vec3f n = dist > 0.0f ? Vec3f(d / dist) : Vec3f::UnitY();
      p.head<3>() = xyz(s) + n * r;
      moved = inside = true;
    }
    if (!moved) break;
  }
  return inside;
}
}  // namespace

void verlet_integrate(std::span<Vec4f> pos, std::span<Vec4f> prev, const Vec3f& gravity,
                      const Wind& wind, bool wind_term, float damping, float dt) {
  verlet<false>(pos, prev, gravity, wind, wind_term, damping, dt);
}

void verlet_integrate_steps(std::span<Vec4f> pos, std::span<Vec4f> step, const Vec3f& gravity,
                            const Wind& wind, bool wind_term, float damping, float dt) {
  verlet<true>(pos, step, gravity, wind, wind_term, damping, dt);
}

float rounding_sized_length(std::span<const float> rest_length) {
  if (rest_length.size() < 2) return 0.0f;
  std::vector<float> sorted(rest_length.begin() + 1, rest_length.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return kRoundingSizedEdge * sorted[sorted.size() / 2];
}

void edge_length(std::span<Vec4f> pos, std::span<const float> rest_length) { edge_sweep(pos, {}, rest_length); }

void edge_length_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const float> rest_length) {
  edge_sweep(pos, step, rest_length);
}

void collide_spheres(std::span<Vec4f> pos, std::span<const Vec4f> world_spheres) {
  if (world_spheres.empty()) return;
  for (Vec4f& p : pos)
    if (p.w() != 0.0f) push_out(p, world_spheres);
}

void collide_spheres_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec4f> world_spheres) {
  if (world_spheres.empty()) return;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (pos[i].w() == 0.0f) continue;
    const Vec3f old = xyz(pos[i]);
    if (push_out(pos[i], world_spheres)) step[i].head<3>() += xyz(pos[i]) - old;
  }
}

}  // namespace hairbench::kernels
