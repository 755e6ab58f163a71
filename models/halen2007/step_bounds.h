// The largest substep each Halén & Wester model's explicit integrator takes stably on a
// given groom, from the model's equations (docs/substeps.md). `substeps: "auto"` divides
// the frame by it (harness/substeps.h).
#pragma once

#include "core/groom.h"
#include "core/params.h"
#include "core/step_bound.h"
#include "core/types.h"

#include <string>

namespace hairbench::halen {

// Verlet (Eq. 4.1) of a vertex held by a zero-rest-length spring of strength k per unit
// mass is x'' = -k x, stable for omega h < 2 with omega = sqrt(k); we keep omega h <= 1.
inline constexpr double kOmegaStep = 1.0;
// The edge correction (Eq. 4.2) moves both ends of an edge along its current direction. A
// substep that carries a free vertex further than a fraction of its shortest edge, under
// gravity and the spring that holds gravity up (2 |g| h^2), can turn that edge over before
// the correction sees it, and the chain folds. The fraction is measured, not derived (the
// fold is a large-deflection effect of the whole chain that no linearisation gives): on
// tressfx_mohawk (shortest free edge 0.45 mm, 20 frames of its shake) halen_spring
// stretches at 7, 8, 9, 10 and 11 substeps, where 2|g|h^2/l_min is 0.25, 0.19, 0.15, 0.12
// and 0.100 (peak edge errors 0.91, 0.76, 0.64, 0.57, 0.53 of the edge), and holds at 12
// (0.084). 0.05 keeps a factor 1.7 under the last ratio that holds (a substep 1.3 times
// shorter), which 16 substeps meet there.
inline constexpr double kEdgeTravel = 0.05;

// For Han & Harada's position-based models, sqrt(kEdgeTravel e_min / (2 |g|)) with e_min
// the shortest of the strands' median free edges: unconditionally stable, their length
// constraints see a substep's travel only after it, and a few Gauss-Seidel iterations
// leave part of it as stretch along the whole strand, which the stretched verdict reads in
// the strand's median edge. A single short edge is not the scale here, as it is for the
// explicit models' fold. No parameter enters.
StepBound travel_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity);

// halen_spring: min(kOmegaStep / sqrt(k_max), sqrt(kEdgeTravel l_min / (2 |g|))), k_max
// the strongest spring (§5.9's falloff holds it at `stiffness` near the root) and l_min
// the shortest rest edge with a free end.
StepBound spring_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity);

// halen_cascade: the spring bound with k_max = (k_up + k_down)(1 + r)^2, r the largest
// ratio of an edge to the edge before it: a reference node d from its space's origin
// pushes back on the segment that carries the space through a lever l (f_A ~ |R| d / l,
// kernels::cascade_accelerations), which multiplies the spring's stiffness on that
// segment by up to (1 + d / l)^2.
// The springs' reaction through the twist of the spaces (kernels::cascade_accelerations)
// adds a stiffness that grows with the strand's curvature and with the springs beyond each
// bend, which no closed form here bounds: the bound takes the larger of the above and the
// stiffest mode of the springs at rest, found by power iteration on their Jacobian
// (cascade_rest_stiffness); kOmegaStep's factor 2 below the stability limit covers the
// bends that motion adds.
StepBound cascade_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity);
// The largest eigenvalue of the springs' stiffness (per unit mass, s^-2) over the strands
// of g at rest with the head at identity, for the moves that keep the edges' lengths.
double cascade_rest_stiffness(const Groom& g, const ParamSet& p);

// halen_forest: explicit Euler of the joint angles (Eq. 4.2.6). The joints see a discrete
// Laplacian of the spring torques whose fastest mode is about 4k; Euler keeps it when the
// damping v dominates it over a step (v >= 4 k h) and 4 v h < 2, so
// h <= min(v / (4 k_max), 1 / (2 v)) (v = 0: no step is stable). The joint stiffness is per
// unit inertia, so the groom enters only through the falloff, which never exceeds k.
StepBound forest_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity);

}  // namespace hairbench::halen
