// Constants and force curves of the muscle actuation model (mimo_core.md §3.2, after Wochner et
// al. 2022). Lengths are normalised fibre lengths (1 = optimal), velocities are in units of the
// muscle's maximal contraction speed VMAX, forces in units of its maximal isometric force FMAX.
#pragma once

namespace cradle::sim::muscle {

inline constexpr double kLengthMin = 0.5;         // lmin: active force vanishes below
inline constexpr double kLengthMax = 1.6;         // lmax: active force vanishes above
inline constexpr double kVelocityForceMax = 1.2;  // fvmax: force gain at fast lengthening
inline constexpr double kPassiveForceMax = 1.3;   // fpmax: passive force scale
inline constexpr double kFiberMin = 0.75;         // lce_min: fibre length at the far joint limit
inline constexpr double kFiberMax = 1.05;         // lce_max: fibre length at the near joint limit
inline constexpr double kActivationTime = 0.01;   // τ_act in seconds
inline constexpr double kEps = 1e-10;             // keeps moment arms finite for zero ranges

// Smooth bump: 0 outside (lo, hi), 1 at mid, built from four quadratic pieces.
double bump(double length, double lo, double mid, double hi);

// Active force-length curve FL: main bump on [0.5, 1.6] plus a small shoulder on [0.5, 0.95].
double force_length(double length);

// Force-velocity curve FV of the normalised velocity v (positive = lengthening): 0 for v ≤ −1,
// (v + 1)² up to 0, then rising to kVelocityForceMax at v = kVelocityForceMax − 1.
double force_velocity(double velocity);

// Passive force FP: 0 up to length 1, cubic to kPassiveForceMax / 4 at 1.3, then linear.
double force_passive(double length);

// Total normalised force F = FL(length) · FV(velocity) · activation + FP(length).
double force(double length, double velocity, double activation);

}  // namespace cradle::sim::muscle
