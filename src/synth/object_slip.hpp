// SPDX-License-Identifier: BSD-3-Clause
// The object slipping in the grasp, for synthetic recordings: at one seeded
// instant the object starts to slide by a fixed distance relative to the
// claw and settles there, eased over a short time. The claw and the logged
// gripper states do not move; only the object's pose in G changes, so the
// frames show it where it slipped to. Seeded, off by default.
//
// Direction: the gripper points down (z_G = -z_W, see scene.hpp), so
// gravity and the turn pull the object out of the fingers along +z_G (the
// approach, away from the palm); the fingers' pads guide it, so it slides
// along them: a random direction within `max_tilt_deg` of +z_G (uniform on
// that cap of the sphere). A larger sideways part would push the object
// into a finger.
//
// Motion: the displacement at time t is d * s((t - start) / duration) with
// s the smoothstep 3x^2 - 2x^3 (0 before the start, 1 after the end: no
// jump in position or speed).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

namespace graspfill::synth {

struct SlipConfig {
  /// How far the object slides [m]; 0: no slip.
  double distance_m{0.0};
  /// The slide's direction lies within this angle of +z_G [deg].
  double max_tilt_deg{15.0};
  /// The start is drawn uniformly in this part of the recording (fractions
  /// of the time from the first depth frame to the last one): mid-turn, so
  /// the model has been seen before and after.
  double start_min_fraction{0.3};
  double start_max_fraction{0.7};
  /// The slide takes this long [s].
  double duration_s{0.3};

  bool any() const { return distance_m != 0.0; }
  /// Throws std::invalid_argument naming the bad field (distance outside
  /// [0, 0.05) m, tilt outside [0, 90] deg, fractions outside
  /// 0 <= min <= max <= 1, duration outside (0, 10] s).
  void Validate() const;
};

class ObjectSlip {
 public:
  /// No slip.
  ObjectSlip() = default;
  /// Draws the direction and the start from `seed` (its own sub-stream)
  /// for a recording whose depth frames span [first_utime, last_utime].
  ObjectSlip(const SlipConfig& config, uint64_t seed, int64_t first_utime, int64_t last_utime);

  const SlipConfig& config() const { return config_; }
  /// Unit direction of the slide in G (+z_G without slip).
  const Eigen::Vector3d& direction_G() const { return direction_G_; }
  /// The slide's start [us] (the first frame's time without slip).
  int64_t start_utime() const { return start_utime_; }
  int64_t end_utime() const;
  /// The full displacement in G [m]: distance_m * direction_G.
  Eigen::Vector3d Displacement_G() const { return config_.distance_m * direction_G_; }
  /// Share of the slide done at `utime`, in [0, 1] (smoothstep).
  double Progress(int64_t utime) const;
  /// The object's motion in G at `utime`: maps a point of the object as
  /// grasped (before the slip) to where it is then, in G. Identity before
  /// the start and without slip.
  Eigen::Isometry3d S_G(int64_t utime) const;
  /// The same once the slide is over.
  Eigen::Isometry3d S_G_final() const;

 private:
  SlipConfig config_;
  Eigen::Vector3d direction_G_{Eigen::Vector3d::UnitZ()};
  int64_t start_utime_{0};
  int64_t duration_us_{0};
};

}  // namespace graspfill::synth
