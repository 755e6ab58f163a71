// The building blocks two papers share (Han & Harada's and Halén & Wester's
// position-based strand models), as pure functions over one strand's plain arrays
// (positions are float4: xyz + inverse mass w). Every model that uses positions calls
// these; none re-implements them.
#pragma once

#include "core/types.h"

#include <span>

namespace hairbench::kernels {

// Pinned vertices (w == 0) follow the head rigidly (Han & Harada §3.2): p = T_H · p^0.
void follow_head(std::span<Vec4f> pos, std::span<Vec4f> prev, std::span<const Vec4f> rest,
                 const Affine3f& head);

// Verlet integration with damping (Halén & Wester Eq. 4.1, Han & Harada §3.2):
//   p' = p + (1 - damping)(p - p_prev) + a dt²   for vertices with w != 0,
// a = gravity + the part of the wind acceleration normal to the vertex's edge (a thin
// cylinder only catches the wind that meets it face-on). The wind term is computed only
// when `wind_term` is set: the caller decides once per step whether there is wind.
void verlet_integrate(std::span<Vec4f> pos, std::span<Vec4f> prev, const Vec3f& gravity,
                      const Wind& wind, bool wind_term, float damping, float dt);

// A rest edge shorter than this fraction of its strand's median rest edge is
// rounding-sized: its direction is mostly the float rounding of its end positions (an
// edge of 2.4e-7 m 1 m from the origin, where a coordinate rounds by up to 6e-8 m, turns
// by up to 0.24 rad when one coordinate of one end rounds). Han & Harada's method 2 and
// Halén & Wester's cascade take no frame from such an edge.
inline constexpr float kRoundingSizedEdge = 1e-3f;

// One strand's rest edges (rest_length[i]: edge (i-1, i), index 0 unused) shorter than
// this are rounding-sized: kRoundingSizedEdge times their median (0 without edges).
float rounding_sized_length(std::span<const float> rest_length);

// Edge length constraints (Müller et al. 2007, Halén & Wester Eq. 4.2) in even/odd edge
// batches (Han & Harada §5), weighted by inverse mass.
void edge_length(std::span<Vec4f> pos, std::span<const float> rest_length);

// Sphere collisions (Han & Harada §3.5): a free vertex inside a sphere moves to the
// closest surface point. Repeated (a few passes at most) so that a push out of one sphere
// does not leave the vertex inside another.
void collide_spheres(std::span<Vec4f> pos, std::span<const Vec4f> world_spheres);

// The same steps in step form: the Verlet state is each vertex's last step s = p - p_prev
// (xyz; w unused) instead of p_prev, and every move of p (the integration, each edge
// correction, each push out of a sphere, a pinned vertex following the head) is added to
// s as it is made. The arithmetic is Verlet's, but the velocity no longer comes from the
// difference of two positions rounded at the head's scale: there each position rounds by
// up to half an ulp (3.7e-9 m at 0.1 m from the head's centre), a velocity error of
// ulp / 2dt per step that does not shrink with dt. At a few dozen substeps a frame that
// noise keeps a weakly held strand moving at ~1e-5 m (docs/limitations.md, "Float
// rounding at many substeps"); in step form the positions still round, but as positions,
// which the forces pull back.
void follow_head_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec4f> rest,
                       const Affine3f& head);
void verlet_integrate_steps(std::span<Vec4f> pos, std::span<Vec4f> step, const Vec3f& gravity,
                            const Wind& wind, bool wind_term, float damping, float dt);
void edge_length_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const float> rest_length);
void collide_spheres_steps(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec4f> world_spheres);

}  // namespace hairbench::kernels
