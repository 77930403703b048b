// SPDX-License-Identifier: BSD-3-Clause
// ParseRigConfig and LoadRigConfig: YAML (yaml-cpp) into a RigConfig, every
// field checked as it is read, every failure naming the file, line and field.
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <functional>
#include <set>
#include <vector>

#include "config/number_text.hpp"
#include "config/rig_config.hpp"
#include "config/rig_config_checks.hpp"
#include "graspfill/core/regular_file.hpp"
#include "graspfill/io/channel_names.hpp"

namespace graspfill::rt {

using namespace internal;  // the ranges and checks (rig_config_checks.hpp)

namespace {

// yaml-cpp's parser refuses deeper nesting (its DepthGuard's default);
// named in the message instead of the library's "bad file".
constexpr int kMaxYamlDepth = 2000;

// Reads nodes into fields; every failure names the file, line and field.
class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void Fail(const YAML::Node& at, const std::string& field, const std::string& message) const {
    throw ConfigError(field, Where(at) + message);
  }

  std::string Where(const YAML::Node& at) const {
    const YAML::Mark mark = at.Mark();
    if (mark.is_null()) return name_ + ": ";
    return name_ + ":" + std::to_string(mark.line + 1) + ": ";
  }

  static std::string Kind(const YAML::Node& n) {
    if (n.IsNull()) return "null";
    if (n.IsMap()) return "a map";
    if (n.IsSequence()) return "a list";
    if (n.IsScalar()) return n.Tag() == "?" ? "'" + n.Scalar() + "'" : "the string \"" + n.Scalar() + "\"";
    return "nothing";
  }

  // Calls `on_key(key, value, field)` for each entry of the map `node`;
  // an unknown or duplicate key, or a node that is not a map, fails.
  // `required`: every key in `keys` must be there.
  void Map(const YAML::Node& node, const std::string& path, const std::vector<std::string>& keys,
           const std::function<void(const std::string&, const YAML::Node&, const std::string&)>& on_key,
           bool required = false) const {
    const std::string where = path.empty() ? "the file" : path;
    if (!node.IsMap()) Fail(node, path, where + ": expected a map of keys, got " + Kind(node));
    std::set<std::string> seen;
    for (const auto& entry : node) {
      const YAML::Node& key_node = entry.first;
      if (!key_node.IsScalar()) Fail(key_node, path, where + ": a key that is not a name");
      const std::string key = key_node.Scalar();
      const std::string field = path.empty() ? key : path + "." + key;
      bool known = false;
      for (const std::string& k : keys) known = known || k == key;
      if (!known) {
        std::string list;
        for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
        Fail(key_node, field, "unknown key '" + field + "' (" + where + " has: " + list + ")");
      }
      if (!seen.insert(key).second) Fail(key_node, field, "duplicate key '" + field + "'");
      on_key(key, entry.second, field);
    }
    if (required) {
      for (const std::string& k : keys) {
        if (seen.count(k) == 0) {
          const std::string field = path + "." + k;
          Fail(node, field, field + ": missing (" + path + " needs all its keys)");
        }
      }
    }
  }

  double Number(const YAML::Node& n, const std::string& field, const Range& r) const {
    const std::string text = PlainScalar(n, field, "a number");
    try {
      return ReadNumber(field, text, r.min, r.max, r.unit);
    } catch (const std::invalid_argument& e) {
      Fail(n, field, e.what());
    }
  }

  int Integer(const YAML::Node& n, const std::string& field, const Range& r) const {
    const std::string text = PlainScalar(n, field, "an integer");
    try {
      return ReadInteger<int>(field, text, static_cast<int>(r.min), static_cast<int>(r.max));
    } catch (const std::invalid_argument& e) {
      Fail(n, field, e.what());
    }
  }

  bool Bool(const YAML::Node& n, const std::string& field) const {
    const std::string text = PlainScalar(n, field, "true or false");
    if (text == "true") return true;
    if (text == "false") return false;
    Fail(n, field, field + " '" + text + "': expected true or false");
  }

  std::string String(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) Fail(n, field, field + ": expected a string, got " + Kind(n));
    return n.Scalar();
  }

  std::string OneOf(const YAML::Node& n, const std::string& field,
                    const std::vector<std::string>& allowed) const {
    const std::string v = String(n, field);
    try {
      CheckOneOf(field, v, allowed);
    } catch (const ConfigError& e) {
      Fail(n, field, e.what());
    }
    return v;
  }

  template <size_t N>
  std::array<double, N> Numbers(const YAML::Node& n, const std::string& field, const Range& r) const {
    if (!n.IsSequence() || n.size() != N) {
      Fail(n, field,
           field + ": expected a list of " + std::to_string(N) + " numbers, got " +
               (n.IsSequence() ? "a list of " + std::to_string(n.size()) : Kind(n)));
    }
    std::array<double, N> out{};
    for (size_t k = 0; k < N; ++k) out[k] = Number(n[k], field + "[" + std::to_string(k) + "]", r);
    return out;
  }

  // Runs a whole-value check, failing at `n`'s line.
  void Check(const YAML::Node& n, const std::function<void()>& check) const {
    try {
      check();
    } catch (const ConfigError& e) {
      Fail(n, e.field(), e.what());
    }
  }

 private:
  std::string PlainScalar(const YAML::Node& n, const std::string& field, const std::string& what) const {
    if (!n.IsScalar() || n.Tag() != "?") {
      Fail(n, field, field + ": expected " + what + ", got " + Kind(n));
    }
    return n.Scalar();
  }

  std::string name_;
};

// The text's one YAML document (null: an empty file).
YAML::Node LoadOneDocument(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      // yaml-cpp's Load would take the first and drop the rest unread.
      const YAML::Mark mark = documents[1].Mark();
      throw ConfigError("", name + (mark.is_null() ? "" : ":" + std::to_string(mark.line + 1)) +
                                ": a second YAML document (after '---'): a rig config is one "
                                "document; put everything in the first");
    }
    if (!documents.empty()) root = documents[0];
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp words its depth limit "bad file".
    throw ConfigError("", name + ":" + std::to_string(e.mark.line + 1) +
                              ": not a rig config: nested more than " + std::to_string(kMaxYamlDepth) +
                              " levels deep (a rig config nests 4: camera.intrinsics_override.fx_px, "
                              "robot.T_C_B.translation_m[0])");
  } catch (const YAML::Exception& e) {
    throw ConfigError("", name + ":" + std::to_string(e.mark.line + 1) + ": not YAML: " + e.msg);
  }
  return root;
}

RigConfig::Intrinsics ReadIntrinsics(const Reader& r, const YAML::Node& x, const std::string& f) {
  RigConfig::Intrinsics K;
  r.Map(
      x, f, {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px"},
      [&](const std::string& kk, const YAML::Node& y, const std::string& ff) {
        if (kk == "width_px")
          K.width_px = r.Integer(y, ff, kImagePx);
        else if (kk == "height_px")
          K.height_px = r.Integer(y, ff, kImagePx);
        else if (kk == "fx_px")
          K.fx_px = r.Number(y, ff, kFocalPx);
        else if (kk == "fy_px")
          K.fy_px = r.Number(y, ff, kFocalPx);
        else if (kk == "cx_px")
          K.cx_px = r.Number(y, ff, kCentrePx);
        else
          K.cy_px = r.Number(y, ff, kCentrePx);
      },
      /*required=*/true);
  return K;
}

void ReadCamera(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Camera* cam) {
  r.Map(v, path,
        {"device", "width_px", "height_px", "fps", "depth_units", "intrinsics_override", "max_depth_pixels",
         "reject_depth_edges", "depth_scale"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "device")
            cam->device = r.String(x, f);
          else if (k == "reject_depth_edges")
            cam->reject_depth_edges = r.Bool(x, f);
          else if (k == "depth_scale")
            cam->depth_scale = r.Number(x, f, kDepthScale);
          else if (k == "max_depth_pixels")
            cam->max_depth_pixels = r.Integer(x, f, kDepthPixels);
          else if (k == "width_px")
            cam->width_px = r.Integer(x, f, kVideoPx);
          else if (k == "height_px")
            cam->height_px = r.Integer(x, f, kVideoPx);
          else if (k == "fps")
            cam->fps = r.Integer(x, f, kFps);
          else if (k == "depth_units")
            cam->depth_units = r.OneOf(x, f, {"mm", "100um"});
          else if (x.IsNull())
            cam->intrinsics_override.reset();
          else
            cam->intrinsics_override = ReadIntrinsics(r, x, f);
        });
}

void ReadRobot(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Robot* robot) {
  r.Map(v, path, {"T_C_B", "clock_offset_s", "max_pose_gap_s"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "clock_offset_s")
            robot->clock_offset_s = r.Number(x, f, kClockOffsetS);
          else if (k == "max_pose_gap_s")
            robot->max_pose_gap_s = r.Number(x, f, kPoseGapS);
          else if (x.IsNull())
            robot->T_C_B.reset();
          else {
            RigConfig::Pose pose;
            r.Map(
                x, f, {"translation_m", "rotation_wxyz"},
                [&](const std::string& kk, const YAML::Node& y, const std::string& ff) {
                  if (kk == "translation_m")
                    pose.translation_m = r.Numbers<3>(y, ff, kTranslationM);
                  else
                    pose.rotation_wxyz = r.Numbers<4>(y, ff, kQuaternion);
                },
                /*required=*/true);
            r.Check(x["rotation_wxyz"], [&] { CheckPose(f, pose); });
            robot->T_C_B = pose;
          }
        });
}

// null: none (the session description's).
std::optional<RigConfig::Box> ReadWorkspace(const Reader& r, const YAML::Node& v, const std::string& path) {
  if (v.IsNull()) return std::nullopt;
  RigConfig::Box box;
  r.Map(
      v, path, {"min_G_m", "max_G_m"},
      [&](const std::string& k, const YAML::Node& x, const std::string& f) {
        (k == "min_G_m" ? box.min_G_m : box.max_G_m) = r.Numbers<3>(x, f, kBoxM);
      },
      /*required=*/true);
  r.Check(v["max_G_m"], [&] { CheckBox(path, box); });
  return box;
}

void ReadTsdf(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Tsdf* tsdf) {
  r.Map(v, path,
        {"voxel_m", "sdf_trunc_voxels", "block_resolution", "depth_sampling_stride", "max_fusion_pixels"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "voxel_m") {
            if (x.IsNull())
              tsdf->voxel_m.reset();
            else
              tsdf->voxel_m = r.Number(x, f, kVoxelM);
          } else if (k == "sdf_trunc_voxels")
            tsdf->sdf_trunc_voxels = r.Number(x, f, kTruncVoxels);
          else if (k == "block_resolution")
            tsdf->block_resolution = r.Integer(x, f, kBlockResolution);
          else if (k == "depth_sampling_stride")
            tsdf->depth_sampling_stride = r.Integer(x, f, kStride);
          else
            tsdf->max_fusion_pixels = r.Integer(x, f, kFusionPixels);
        });
}

void ReadRepair(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Repair* repair) {
  r.Map(v, path,
        {"enabled", "mode", "use_evidence", "safe_bound_voxel_m", "top_rim_band_m", "close_unknown_top",
         "incremental"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "enabled")
            repair->enabled = r.Bool(x, f);
          else if (k == "mode")
            repair->mode = r.OneOf(x, f, {"best", "paper"});
          else if (k == "use_evidence")
            repair->use_evidence = r.Bool(x, f);
          else if (k == "safe_bound_voxel_m") {
            repair->safe_bound_voxel_m = r.Number(x, f, kSafeBoundM);
            r.Check(x, [&] { CheckSafeBound(f, repair->safe_bound_voxel_m); });
          } else if (k == "top_rim_band_m")
            repair->top_rim_band_m = r.Number(x, f, kRimBandM);
          else if (k == "incremental")
            repair->incremental = r.Bool(x, f);
          else
            r.Bool(x, f);  // close_unknown_top: read and ignored since the top search (2026-12)
        });
}

void ReadChannels(const Reader& r, const YAML::Node& v, const std::string& path,
                  RigConfig::Channels* channels) {
  r.Map(v, path, {"depth", "gripper_state", "object_cloud", "status", "session", "collision_mesh"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          std::string value = r.String(x, f);
          r.Check(x, [&] { CheckChannel(f, value); });
          if (k == "depth")
            channels->depth = value;
          else if (k == "gripper_state")
            channels->gripper_state = value;
          else if (k == "object_cloud")
            channels->object_cloud = value;
          else if (k == "status")
            channels->status = value;
          else if (k == "session")
            channels->session = value;
          else
            channels->collision_mesh = value;
        });
  // Two the same: named at the line of the later one the file sets
  // (the other may be a default).
  if (const auto problem = io::FindChannelNameProblem(ToChannelNames(*channels))) {
    const bool later_set = v[problem->role].IsDefined();
    const std::string& role = later_set ? problem->role : problem->same_as;
    const std::string& other = later_set ? problem->same_as : problem->role;
    r.Check(v[role], [&] { throw SameChannelError(role, problem->name, other); });
  }
}

void ReadClaw(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Claw* claw) {
  r.Map(v, path, {"spec", "mesh_root"}, [&](const std::string& k, const YAML::Node& x, const std::string& f) {
    (k == "spec" ? claw->spec : claw->mesh_root) = r.String(x, f);
  });
}

void ReadRefine(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Refine* refine) {
  r.Map(v, path, {"enabled", "min_correction_m", "min_correction_deg", "track_object", "apply_depth_scale"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "enabled")
            refine->enabled = r.Bool(x, f);
          else if (k == "min_correction_m")
            refine->min_correction_m = r.Number(x, f, kCorrectionM);
          else if (k == "min_correction_deg")
            refine->min_correction_deg = r.Number(x, f, kCorrectionDeg);
          else if (k == "apply_depth_scale")
            refine->apply_depth_scale = r.Bool(x, f);
          else
            refine->track_object = r.Bool(x, f);
        });
}

void ReadCollisionMesh(const Reader& r, const YAML::Node& v, const std::string& path,
                       RigConfig::CollisionMesh* mesh) {
  r.Map(v, path, {"max_triangles", "convex_hull"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "max_triangles")
            mesh->max_triangles = r.Integer(x, f, kMeshTriangles);
          else
            mesh->convex_hull = r.Bool(x, f);
        });
}

void ReadCompute(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Compute* compute) {
  r.Map(v, path, {"num_threads"}, [&](const std::string&, const YAML::Node& x, const std::string& f) {
    compute->num_threads = r.Integer(x, f, kNumThreads);
  });
}

void ReadRates(const Reader& r, const YAML::Node& v, const std::string& path, RigConfig::Rates* rates) {
  r.Map(v, path, {"publish_every_n_frames", "status_period_s"},
        [&](const std::string& k, const YAML::Node& x, const std::string& f) {
          if (k == "publish_every_n_frames") {
            rates->publish_every_n_frames = r.Integer(x, f, kPublishEvery);
          } else {
            rates->status_period_s = r.Number(x, f, kStatusPeriodS);
          }
        });
}

}  // namespace

RigConfig ParseRigConfig(const std::string& text, const std::string& name) {
  const YAML::Node root = LoadOneDocument(text, name);
  RigConfig c;
  if (root.IsNull()) return c;  // an empty file: the defaults
  const Reader r(name);
  r.Map(root, "",
        {"camera", "robot", "claw", "workspace", "tsdf", "repair", "refine", "channels", "collision_mesh",
         "rates", "compute"},
        [&](const std::string& key, const YAML::Node& v, const std::string& path) {
          if (key == "camera")
            ReadCamera(r, v, path, &c.camera);
          else if (key == "robot")
            ReadRobot(r, v, path, &c.robot);
          else if (key == "workspace")
            c.workspace = ReadWorkspace(r, v, path);
          else if (key == "tsdf")
            ReadTsdf(r, v, path, &c.tsdf);
          else if (key == "repair")
            ReadRepair(r, v, path, &c.repair);
          else if (key == "channels")
            ReadChannels(r, v, path, &c.channels);
          else if (key == "claw")
            ReadClaw(r, v, path, &c.claw);
          else if (key == "refine")
            ReadRefine(r, v, path, &c.refine);
          else if (key == "collision_mesh")
            ReadCollisionMesh(r, v, path, &c.collision_mesh);
          else if (key == "compute")
            ReadCompute(r, v, path, &c.compute);
          else
            ReadRates(r, v, path, &c.rates);
        });
  try {
    c.Validate();  // every field was checked as read; this is the net under it
  } catch (const ConfigError& e) {
    throw ConfigError(e.field(), name + ": " + e.what());
  }
  return c;
}

RigConfig LoadRigConfig(const std::string& path) {
  // A config is a few kB; anything huge is a wrong path. A FIFO or a device
  // is refused unopened (it could block or never end).
  constexpr int64_t kMaxBytes = 1 << 20;
  std::string text;
  try {
    text = ReadRegularFile(path, kMaxBytes, "cannot read config");
  } catch (const std::runtime_error& e) {
    throw ConfigError("", e.what());
  }
  return ParseRigConfig(text, path);
}

}  // namespace graspfill::rt
