#include "kernels/muller2012/ftl_kernels.h"

#include <algorithm>
#include <cmath>

namespace hairbench::kernels::muller {

namespace {

// Passes over the spheres when a vertex is moved out of them, so that leaving one sphere
// does not leave it inside another.
constexpr int kPushPasses = 4;

// `inline` raises GCC's inlining budget for it: at -O2 it was left a call, and the whole
// step ran 2.4 times slower (71 against 30 ns a vertex). follow, onto_contact_circle and
// collide are `inline` too, so that the FTL pass over strands side by side (below) is one
// loop body without calls, which the core can overlap from strand to strand.
inline Vec3f xyz(const Vec4f& v) { return v.head<3>(); }

// The edge a vertex meets the wind with: the one into it; the root's is the one out of it.
Vec3f wind_edge(std::span<const Vec4f> x, std::size_t i) {
  if (i > 0) return xyz(x[i]) - xyz(x[i - 1]);
  return x.size() > 1 ? Vec3f(xyz(x[1]) - xyz(x[0])) : Vec3f::Zero();
}

// The part of the wind acceleration normal to `edge` (a thin cylinder only catches the
// wind that meets it face-on); all of it on an edge of no length, which has no direction.
Vec3f normal_wind(const Vec3f& wind, const Vec3f& edge) {
  const float len2 = edge.squaredNorm();
  if (!(len2 > 0.0f)) return wind;
  const Vec3f t = edge / std::sqrt(len2);
  return wind - wind.dot(t) * t;
}

// §3: the point at distance `length` from `leader` in the direction of `target`. A target
// on the leader gives no direction; the vertex's rest edge under the head's rotation does.
inline Vec3f follow(const Vec3f& leader, const Vec3f& target, float length, std::span<const Vec4f> rest,
                    std::size_t i, const Affine3f& head) {
  const Vec3f dir = target - leader;
  const float len = dir.norm();
  if (len > 0.0f) return leader + dir * (length / len);
  const Vec3f rest_dir = head.linear() * (xyz(rest[i]) - xyz(rest[i - 1]));
  const float rest_len = rest_dir.norm();
  return rest_len > 0.0f ? Vec3f(leader + rest_dir * (length / rest_len)) : leader;
}

// A free root (no leader): moves q to the closest surface point of every sphere it is
// inside.
void push_out(Vec3f& q, std::span<const Vec4f> spheres) {
  for (int pass = 0; pass < kPushPasses; ++pass) {
    bool moved = false;
    for (const Vec4f& s : spheres) {
      const Vec3f off = q - xyz(s);
      const float dist2 = off.squaredNorm();
      if (dist2 >= s.w() * s.w()) continue;
      const float dist = std::sqrt(dist2);
      // A point at the centre has no closest surface point; push it straight up.
      q = xyz(s) + (dist > 0.0f ? Vec3f(off / dist) : Vec3f::UnitY()) * s.w();
      moved = true;
    }
    if (!moved) break;
  }
}

// Ours, not the paper's: a vertex q placed inside sphere s (centre xyz, radius w) goes to
// the sphere's surface while staying at `length` from its leader: to the nearest point of
// the circle where the sphere of radius `length` around the leader meets the sphere's
// surface. Pushing q to the surface and putting it back at its rest length from the
// leader, over and over, ends on that circle; this goes there in one go, because those
// rounds converge slowly where a strand wraps a moving sphere (a 16-vertex strand draped
// on a sphere shaken by 5 cm at 2 Hz: still 6 mm deep after 4 rounds, 0.4 mm after 64).
// Where the whole length sphere lies inside, the vertex goes to its point farthest from
// the centre; where the two spheres do not meet, q can be inside only by rounding and
// stays.
inline Vec3f onto_contact_circle(const Vec3f& leader, const Vec3f& q, float length, const Vec4f& s) {
  const Vec3f axis = xyz(s) - leader;
  const float dist = axis.norm();
  if (!(dist > 0.0f) || !(length > 0.0f)) return q;
  const Vec3f u = axis / dist;
  // Law of cosines: the angle at the leader between u and a point of the circle.
  const float cos_t = (length * length + dist * dist - s.w() * s.w()) / (2.0f * length * dist);
  if (cos_t < -1.0f) return leader - u * length;
  if (cos_t > 1.0f) return q;
  const Vec3f rel = q - leader;
  const Vec3f side = rel - rel.dot(u) * u;
  const float side_len = side.norm();
  const Vec3f w = side_len > 0.0f ? Vec3f(side / side_len) : u.unitOrthogonal();
  const float sin_t = std::sqrt(1.0f - cos_t * cos_t);
  return leader + (cos_t * u + sin_t * w) * length;
}

// Ours: the collision step inside the FTL pass (after §3 placed q at its rest length).
inline Vec3f collide(const Vec3f& leader, Vec3f q, float length, std::span<const Vec4f> spheres) {
  for (int pass = 0; pass < kPushPasses; ++pass) {
    bool moved = false;
    for (const Vec4f& s : spheres) {
      if ((q - xyz(s)).squaredNorm() >= s.w() * s.w()) continue;
      q = onto_contact_circle(leader, q, length, s);
      moved = true;
    }
    if (!moved) break;
  }
  return q;
}

}  // namespace

Affine3f head_transform(const float* column_major_4x4) {
  Affine3f head;
  head.matrix() = Eigen::Map<const Eigen::Matrix4f>(column_major_4x4);
  return head;
}

void rest_lengths(std::span<const Vec4f> rest, std::span<float> out) {
  if (out.empty()) return;
  out[0] = 0.0f;
  for (std::size_t i = 1; i < rest.size(); ++i) out[i] = (xyz(rest[i]) - xyz(rest[i - 1])).norm();
}

void predict(std::span<const Vec4f> x, std::span<const Vec4f> v, std::span<const Vec4f> rest,
             const StepInput& in, std::span<Vec4f> p) {
  const bool wind_term = in.wind.squaredNorm() > 0.0f;
  const float dt2 = in.dt * in.dt;
  for (std::size_t i = 0; i < x.size(); ++i) {
    p[i] = x[i];
    // Pinned vertices are kinematic: exact on the head, they are exact leaders for §3.
    if (x[i].w() == 0.0f) {
      p[i].head<3>() = in.head * xyz(rest[i]);
      continue;
    }
    const Vec3f a = wind_term ? Vec3f(in.gravity + normal_wind(in.wind, wind_edge(x, i))) : in.gravity;
    p[i].head<3>() = xyz(x[i]) + in.dt * xyz(v[i]) + dt2 * a;
  }
}

namespace {

// Vertex i of follow_the_leader's pass; every vertex before it is placed.
inline void follow_vertex(std::span<Vec4f> p, std::span<Vec4f> d, std::span<const Vec4f> rest,
                          std::span<const float> rest_length, const StepInput& in, std::size_t i) {
  d[i].setZero();
  if (p[i].w() == 0.0f) return;  // pinned: a leader FTL never moves
  Vec3f q = xyz(p[i]);
  if (i == 0) {
    // A free root has no leader: FTL leaves it where it was predicted, the spheres
    // alone move it.
    push_out(q, in.spheres);
    p[i].head<3>() = q;
    return;
  }
  const Vec3f leader = xyz(p[i - 1]);
  const Vec3f placed = follow(leader, q, rest_length[i], rest, i, in.head);
  // d_i is the FTL move only, not the collision's: the sphere, not the edge, pushes a
  // vertex out, so nothing of that push is the leader's to take back in §4's velocity
  // term (taking it too bent strands that wrap a moving head twice as much per edge).
  d[i].head<3>() = placed - q;
  p[i].head<3>() = in.spheres.empty() ? placed : collide(leader, placed, rest_length[i], in.spheres);
}

}  // namespace

void follow_the_leader(std::span<Vec4f> p, std::span<Vec4f> d, std::span<const Vec4f> rest,
                       std::span<const float> rest_length, const StepInput& in) {
  for (std::size_t i = 0; i < p.size(); ++i) follow_vertex(p, d, rest, rest_length, in, i);
}

void follow_the_leader(std::span<const FtlStrand> strands) {
  std::size_t longest = 0;
  for (const FtlStrand& s : strands) longest = std::max(longest, s.p.size());
  for (std::size_t i = 0; i < longest; ++i)
    for (const FtlStrand& s : strands)
      if (i < s.p.size()) follow_vertex(s.p, s.d, s.rest, s.rest_length, *s.in, i);
}

void update_velocity(std::span<Vec4f> x, std::span<Vec4f> v, std::span<const Vec4f> p,
                     std::span<const Vec4f> d, const StepInput& in) {
  const float keep = 1.0f - in.damping;
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n; ++i) {
    Vec3f move = xyz(p[i]) - xyz(x[i]);
    if (x[i].w() != 0.0f) {
      // §4: FTL restores an edge by moving the child alone (the tip never pulls the root
      // back). Taking s_damping of the child's move d_{i+1} off this vertex's velocity
      // gives it a share of that move (and damps, as the paper observes). d_{i+1} is zero
      // past the tip and for a pinned child.
      if (i + 1 < n) move -= in.s_damping * xyz(d[i + 1]);
      v[i].head<3>() = keep * (move / in.dt);
    } else {
      v[i].head<3>() = move / in.dt;
    }
    x[i].head<3>() = xyz(p[i]);
  }
}

void dftl_step(std::span<Vec4f> x, std::span<Vec4f> v, std::span<Vec4f> p, std::span<Vec4f> d,
               std::span<const Vec4f> rest, std::span<const float> rest_length, const StepInput& in) {
  predict(x, v, rest, in, p);
  follow_the_leader(p, d, rest, rest_length, in);
  update_velocity(x, v, p, d, in);
}

}  // namespace hairbench::kernels::muller
