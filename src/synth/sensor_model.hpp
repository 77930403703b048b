// SPDX-License-Identifier: BSD-3-Clause
// A Kinect-v1-like structured-light depth sensor model, applied to an ideal
// (noise-free) rendering:
//   - axial noise, Nguyen, Izadi, Lovell, "Modeling Kinect Sensor Noise for
//     Improved 3D Reconstruction and Tracking", 3DIMPVT 2012, eq. (2):
//       sigma_z(z, theta) = 0.0012 + 0.0019 (z - 0.4)^2
//                           + 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2
//     [m; z in m, theta the angle between the ray and the surface normal];
//   - disparity quantization: the Kinect measures disparity d = b f / z in
//     steps of 1/8 pixel (baseline b = 0.075 m, f = fx of the intrinsics),
//     so depth comes in steps of ~z^2 / (8 b f);
//   - dropouts: at grazing angles (a probability ramp up to certain loss),
//     at depth discontinuities, and at random; and the range limits;
//   - mixed ("flying") pixels, off by default: a ray that straddles a depth
//     edge returns a depth between its two sides, as time-of-flight cameras
//     do (Hansard et al., "Time-of-Flight Cameras: Principles, Methods and
//     Applications", Springer 2012, sec. 1.3) and structured-light and
//     stereo sensors do where their matching window spans the edge;
//   - projector shadow, off by default: a structured-light sensor sees
//     depth only where its projector, `baseline_m` beside the camera along
//     +x of C, lights the surface too (Khoshelham & Elberink, "Accuracy and
//     Resolution of Kinect Depth Data", Sensors 2012: the shadow bands
//     beside every occluding edge);
//   - dark or shiny patches, off by default: blobs fixed on the object's
//     surface that return nothing (too little infrared back, or a mirror
//     reflection away from the camera; Khoshelham & Elberink again, and
//     Mallick et al., "Characterizations of Noise in Kinect Depth Images",
//     IEEE Sensors Journal 2014);
//   - an uncalibrated sensor, off by default: depth scaled (a disparity
//     offset or baseline error reads as a scale over a workspace's depth
//     range), the frames' focal lengths stated off the true ones, and a
//     slow depth wobble of the whole frame (thermal drift of structured-
//     light sensors, sub-mm over seconds).
#pragma once

#include <cstdint>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::synth {

/// What a ray of the ideal rendering hit first.
enum class SurfaceLabel : uint8_t {
  kNone = 0,        ///< nothing within the scene (no return)
  kObject = 1,      ///< the grasped object
  kClaw = 2,        ///< palm or fingers
  kArm = 3,         ///< the robot arm behind the palm
  kBackground = 4,  ///< wall
};

/// Why a hit returns nothing whatever the noise (IdealDepthImage::unlit).
enum UnlitFlag : uint8_t {
  kLit = 0,
  kProjectorShadow = 1,  ///< the projector's ray to the point is blocked
  kDarkPatch = 2,        ///< the point lies in a dark or shiny patch
};

/// A noise-free rendering: per pixel (row-major, width*height) the true
/// z-depth in the camera frame (0 where nothing was hit), the cosine of the
/// angle between the viewing ray and the surface normal, the label, and
/// (empty unless the sensor asks for them) UnlitFlag bits.
struct IdealDepthImage {
  CameraIntrinsics intrinsics;
  std::vector<float> depth_m;
  std::vector<float> cos_incidence;
  std::vector<SurfaceLabel> label;
  std::vector<uint8_t> unlit;
};

/// Sensor parameters; the defaults are a Kinect v1 (see file comment).
/// Ideal() switches off every random effect and the quantization.
struct SensorModelConfig {
  bool noise{true};                  ///< add axial Gaussian noise
  double sigma_base_m{0.0012};       ///< Nguyen 2012 constant term [m]
  double sigma_quadratic_m{0.0019};  ///< coefficient of (z - z_ref)^2 [1/m]
  double sigma_reference_depth_m{0.4};
  double sigma_angular_m{0.0001};      ///< coefficient of the angle term
  bool quantize{true};                 ///< quantize disparity
  double baseline_m{0.075};            ///< projector-camera baseline
  double disparity_steps_per_px{8.0};  ///< 1/8-pixel disparity resolution
  double min_range_m{0.3};             ///< nearer returns are invalid
  double max_range_m{3.0};             ///< farther returns are invalid
  /// Grazing angles: no loss below start, certain loss above full, linear
  /// in between [deg between ray and surface normal].
  double grazing_start_deg{75.0};
  double grazing_full_deg{82.0};
  /// A pixel with a 4-neighbour farther or nearer than this, or without a
  /// return, sits on a depth edge [m] ...
  double edge_jump_m{0.02};
  /// ... and is lost with this probability (structured-light edge loss).
  double edge_dropout_prob{0.5};
  /// Probability that any pixel is lost at random.
  double random_dropout_prob{0.005};
  /// Probability that a pixel on a jump between two returns, not lost,
  /// returns a mixed depth: its own plus a uniform share of the jump to
  /// the 4-neighbour farthest from it in depth (0: as a Kinect v1, whose
  /// edges are lost rather than mixed).
  double mixed_pixel_prob{0.0};
  /// No return where the projector (baseline_m along +x of C) cannot
  /// light the surface.
  bool projector_shadow{false};
  /// The share of the object's surface in dark or shiny patches that
  /// return nothing (0..0.5), and their size [m]: a smooth random field
  /// over the object's own frame, so a patch stays on the object as it
  /// turns.
  double dark_patch_share{0.0};
  double dark_patch_size_m{0.01};
  /// Every returned depth is this many times its truth (1.01: 1% long).
  double depth_scale{1.0};
  /// The frames state focal lengths (fx, fy) this many times the ones they
  /// were rendered with; the principal point is right.
  double intrinsics_scale{1.0};
  /// A slow offset of every depth in a frame: wobble_m sin(2 pi t /
  /// wobble_period_s), t the frame's time [m, s].
  double wobble_m{0.0};
  double wobble_period_s{2.0};

  /// Noise-free, unquantized, no dropouts; only the range limits remain.
  static SensorModelConfig Ideal();
  /// Throws std::invalid_argument on a bad value (negative sigma,
  /// probabilities outside [0, 1], empty range, ...).
  void Validate() const;
};

/// Axial noise standard deviation at depth z [m] and incidence angle
/// theta [rad] (Nguyen 2012 eq. 2, with the config's coefficients).
double AxialNoiseSigma(const SensorModelConfig& config, double z_m, double incidence_rad);

/// Depth after rounding the disparity to the sensor's resolution [m].
double QuantizeDepth(const SensorModelConfig& config, double fx_px, double z_m);

/// Turns an ideal rendering into a sensor frame. Deterministic: the same
/// inputs and `seed` give a byte-identical frame.
DepthFrame ApplySensorModel(const SensorModelConfig& config, const IdealDepthImage& ideal, uint64_t seed,
                            int64_t utime);

}  // namespace graspfill::synth
