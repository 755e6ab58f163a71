// Müller, Kim & Chentanez 2012, "Fast Simulation of Inextensible Hair and Fur" (VRIPHYS
// 2012): Dynamic Follow-The-Leader (DFTL), as pure functions over one strand's plain
// arrays. Positions are float4, xyz in metres and w = inverse mass (0: pinned to the
// head); velocities are float4 with w unused. Vertex 0 is the root, the last the tip.
//
// One step is Algorithm 1's three loops, in order:
//   predict             p_i = x_i + Δt v_i + Δt² a_i                          (§4, Alg. 1)
//   follow_the_leader   each p_i moved onto the sphere of its rest length around
//                       its already-placed parent, root to tip, one pass     (§3)
//                       d_i = the move that made                              (§4)
//   update_velocity     v_i = (p_i - x_i)/Δt - s_damping d_{i+1}/Δt, x_i = p_i (§4, Alg. 1)
// dftl_step runs the three on one strand.
//
// DFTL keeps the strand inextensible and nothing else: it has no bending, twisting or
// shape term, so a strand keeps its rest shape only where pins hold it.
#pragma once

#include "core/types.h"

#include <span>

namespace hairbench::kernels::muller {

// What one step of one strand is told. `spheres` are world-space centre xyz and radius.
struct StepInput {
  Affine3f head = Affine3f::Identity();  // head rest -> world at the end of the step
  Vec3f gravity = Vec3f::Zero();         // m/s²
  Vec3f wind = Vec3f::Zero();            // acceleration, m/s²; zero when there is none
  std::span<const Vec4f> spheres;
  float dt = 0.0f;                       // s
  float s_damping = 0.9f;                // §4's s_damping, the paper's value
  float damping = 0.0f;                  // ours: v *= 1 - damping per step
};

// The head transform from a 4x4 column-major float matrix (the plugin ABI's layout, which
// is also Eigen's storage of an Affine3f).
Affine3f head_transform(const float* column_major_4x4);

// Rest edge lengths of one strand: out[i] = |rest_i - rest_{i-1}|, out[0] = 0 (unused).
// FTL needs nothing else from the rest state but the pinned vertices' rest positions.
void rest_lengths(std::span<const Vec4f> rest, std::span<float> out);

// Algorithm 1, prediction: p_i = x_i + Δt v_i + Δt² a_i for free vertices, with
// a_i = gravity + the part of the wind normal to the vertex's edge (ours, as every
// hairbench model: a thin cylinder only catches the wind that meets it face-on).
// Pinned vertices are placed exactly at head · rest_i. w of p is copied from x.
void predict(std::span<const Vec4f> x, std::span<const Vec4f> v, std::span<const Vec4f> rest,
             const StepInput& in, std::span<Vec4f> p);

// §3, follow the leader, with our collisions: root to tip, each free p_i is moved onto
// the sphere of radius rest_length[i] around the already-placed p_{i-1}, along the
// direction from p_{i-1} to the predicted p_i. One pass: every edge into a free vertex is
// at its rest length when it ends, nothing iterates. Pinned vertices (anywhere in the
// strand) are not moved and the pass continues from them; the edge into a pinned vertex
// that follows a free one is not held (FTL has one direction: a vertex never looks at its
// child). A free root has no leader and stays where it was predicted.
// Collisions (ours, not the paper's): a vertex placed inside a sphere moves to the
// nearest point that is on the sphere's surface and still at its rest length from its
// leader, before its child is placed, so the length stays exact and the child follows the
// corrected vertex. d_i is the FTL move of p_i alone (0 for pinned vertices and a free
// root), for update_velocity: the collision's move is the sphere's, not the edge's.
void follow_the_leader(std::span<Vec4f> p, std::span<Vec4f> d, std::span<const Vec4f> rest,
                       std::span<const float> rest_length, const StepInput& in);

// One strand's arrays and input, for follow_the_leader over several strands.
struct FtlStrand {
  std::span<Vec4f> p, d;
  std::span<const Vec4f> rest;
  std::span<const float> rest_length;
  const StepInput* in = nullptr;
};

// follow_the_leader on each of `strands`, vertex i of every strand before vertex i + 1 of
// any. One strand's pass is a chain of dependent square roots and divisions (a vertex
// waits for its leader), so a core left with one chain idles; strands side by side give
// it independent work. Each strand gets follow_the_leader's operations: the same bits.
void follow_the_leader(std::span<const FtlStrand> strands);

// Algorithm 1, velocity update: v_i = (p_i - x_i)/Δt - s_damping d_{i+1}/Δt for a free
// vertex with a free child; the tip, and a free vertex whose child is pinned, have no
// correction term (their child was not moved by FTL). Then v *= 1 - damping (ours) and
// x_i = p_i. A pinned vertex's velocity is its move over the step (the head's).
void update_velocity(std::span<Vec4f> x, std::span<Vec4f> v, std::span<const Vec4f> p,
                     std::span<const Vec4f> d, const StepInput& in);

// One DFTL step of one strand (Algorithm 1); p and d are scratch of the strand's size.
void dftl_step(std::span<Vec4f> x, std::span<Vec4f> v, std::span<Vec4f> p, std::span<Vec4f> d,
               std::span<const Vec4f> rest, std::span<const float> rest_length, const StepInput& in);

}  // namespace hairbench::kernels::muller
