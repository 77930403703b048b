// SPDX-License-Identifier: BSD-3-Clause
// Writes the seed corpora of tests/fuzz/corpus/ with graspfill's own
// encoders (run once by hand when a format changes; the output is
// committed): make_seeds <corpus folder>.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <graspfill/session_description_t.hpp>
#include <string>
#include <utility>
#include <vector>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/collision_mesh_message.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"

using namespace graspfill;
namespace fs = std::filesystem;

namespace {

void Write(const fs::path& dir, const std::string& name, const std::vector<uint8_t>& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
void WriteText(const fs::path& dir, const std::string& name, const std::string& text) {
  Write(dir, name, std::vector<uint8_t>(text.begin(), text.end()));
}

// fuzz_cloud_chunks's record: length (2 bytes little-endian), the message.
void AppendMessage(std::vector<uint8_t>* out, const std::vector<uint8_t>& message) {
  out->push_back(static_cast<uint8_t>(message.size() & 0xff));
  out->push_back(static_cast<uint8_t>(message.size() >> 8));
  out->insert(out->end(), message.begin(), message.end());
}
// fuzz_live_bus's record: channel (0 depth, 1 gripper state, 2 session
// description), then the message as above.
void AppendRecord(std::vector<uint8_t>* out, uint8_t channel, const std::vector<uint8_t>& message) {
  out->push_back(channel);
  AppendMessage(out, message);
}

void PutBigEndian(std::vector<uint8_t>* out, uint64_t v, int n) {
  for (int i = n - 1; i >= 0; --i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void AppendEvent(std::vector<uint8_t>* log, int64_t number, const std::string& channel,
                 const std::vector<uint8_t>& data) {
  PutBigEndian(log, 0xEDA1DA01u, 4);
  PutBigEndian(log, static_cast<uint64_t>(number), 8);
  PutBigEndian(log, static_cast<uint64_t>(1000 * number), 8);
  PutBigEndian(log, channel.size(), 4);
  PutBigEndian(log, data.size(), 4);
  log->insert(log->end(), channel.begin(), channel.end());
  log->insert(log->end(), data.begin(), data.end());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const fs::path root = argv[1];
  DepthFrame frame;
  frame.utime = 1700000000000000;
  frame.intrinsics = CameraIntrinsics{8, 6, 10.0, 10.0, 3.5, 2.5};
  frame.depth_m.assign(48, 0.5f);
  frame.depth_m[7] = 0.0f;
  GripperState state;
  state.utime = 1700000000001000;
  state.T_C_G.translation() = Eigen::Vector3d(0.0, 0.05, 0.4);
  state.opening_m = 0.03;
  state.joint_values = {0.01, 0.02};
  ObjectCloud cloud;
  cloud.points_G = {{0, 0, 0}, {0.01f, 0, 0.02f}, {0, 0.01f, 0.03f}};
  cloud.normals_G = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
  cloud.provenance = {Provenance::kObserved, Provenance::kSurface, Provenance::kSymmetry};
  cloud.confidence = {1.0f, 0.6f, 0.5f};
  cloud.timings = {{"extract", 1.5}};
  HoleSummary hole;
  hole.points_added = 2;
  cloud.holes = {hole};
  io::SessionDescription session;
  session.utime = 1700000000000000;
  session.software_version = io::SoftwareVersion();
  session.claw_name = "three-finger";
  session.claw_text = "{\"finger_length_m\": 0.08}";
  session.intrinsics = CameraIntrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};
  session.workspace_G =
      Eigen::AlignedBox3d(Eigen::Vector3d(-0.1, -0.1, 0.0), Eigen::Vector3d(0.1, 0.1, 0.25));
  session.voxel_m = 0.002;
  io::ModuleStatus status;
  status.frames_in = 10;
  status.state = "running";
  status.bad_messages.by_reason[static_cast<size_t>(io::MessageError::kBadPose)] = 2;
  status.decode_errors = 2;

  const auto depth_raw = io::EncodeDepthImage(frame, io::DepthEncoding::kRaw16);
  const auto depth_zlib = io::EncodeDepthImage(frame, io::DepthEncoding::kZlib16);
  Write(root / "depth_image", "raw16", depth_raw);
  Write(root / "depth_image", "zlib16", depth_zlib);
  Write(root / "gripper_state", "camera", io::EncodeGripperState(state));
  Write(root / "object_cloud", "three_points", io::EncodeObjectCloud(cloud));
  Write(root / "session_description", "full", io::EncodeSessionDescription(session));
  Write(root / "module_status", "running", io::EncodeModuleStatus(status));

  const io::ChannelNames channels;
  std::vector<uint8_t> log;
  AppendEvent(&log, 0, channels.session, io::EncodeSessionDescription(session));
  AppendEvent(&log, 1, channels.depth, depth_zlib);
  AppendEvent(&log, 2, channels.gripper_state, io::EncodeGripperState(state));
  AppendEvent(&log, 3, "OTHER", {1, 2, 3});
  Write(root / "lcm_log_reader", "four_events", log);
  // A session on the bus: a description (built-in, URDF of primitives, a
  // claw name that is a path), a state, a frame, a state after it.
  {
    GripperState before = state, after = state;
    before.utime = frame.utime - 1000;
    after.utime = frame.utime + 1000;
    io::SessionDescription parallel = session;
    parallel.claw_name = "parallel";
    io::SessionDescription urdf = session;
    urdf.claw_kind = io::SessionClawKind::kUrdf;
    urdf.claw_name = "boxes";
    urdf.claw_text =
        "<robot name=\"boxes\"><link name=\"a\"><collision><geometry><box size=\"0.1 0.1 "
        "0.02\"/></geometry></collision></link><link name=\"b\"><collision><geometry><mesh "
        "filename=\"package://p/b.stl\"/></geometry></collision></link><joint name=\"j\" "
        "type=\"prismatic\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"1 0 0\"/>"
        "<limit lower=\"0\" upper=\"0.04\" effort=\"1\" velocity=\"1\"/></joint></robot>";
    graspfill::session_description_t traversal{};
    traversal.claw_kind = graspfill::session_description_t::CLAW_DESCRIPTION;
    traversal.claw_name = "../../victim";
    traversal.claw_text = R"({"links": [{"name": "palm"}]})";
    traversal.T_C_B_orientation[0] = 1.0;
    std::vector<uint8_t> traversal_bytes(static_cast<size_t>(traversal.getEncodedSize()));
    traversal.encode(traversal_bytes.data(), 0, static_cast<int>(traversal_bytes.size()));
    for (const auto& [name, description] : std::vector<std::pair<std::string, std::vector<uint8_t>>>{
             {"builtin", io::EncodeSessionDescription(parallel)},
             {"urdf", io::EncodeSessionDescription(urdf)},
             {"traversal", traversal_bytes}}) {
      std::vector<uint8_t> records;
      AppendRecord(&records, 2, description);
      AppendRecord(&records, 1, io::EncodeGripperState(before));
      AppendRecord(&records, 0, depth_zlib);
      AppendRecord(&records, 1, io::EncodeGripperState(after));
      Write(root / "live_bus", name, records);
    }
  }

  // The cloud channel: a model's slices (in order; shuffled with repeats,
  // then the model whole), one cloud dropped for another, malformed slices.
  {
    const std::vector<uint8_t> whole = io::EncodeObjectCloud(cloud);
    const auto slices = io::EncodeCloudChunks(whole, (whole.size() + 3) / 4);
    if (slices.size() != 4) return 1;
    ObjectCloud other_cloud = cloud;
    other_cloud.seq = cloud.seq + 1;
    const auto other = io::EncodeCloudChunks(io::EncodeObjectCloud(other_cloud), (whole.size() + 2) / 3);
    const fs::path dir = root / "cloud_chunks";
    std::vector<uint8_t> in_order, shuffled, dropped, malformed;
    for (const auto& s : slices) AppendMessage(&in_order, s);
    Write(dir, "slices_in_order", in_order);
    for (int i : {3, 1, 1, 0, 3, 2}) AppendMessage(&shuffled, slices[static_cast<size_t>(i)]);
    AppendMessage(&shuffled, whole);
    Write(dir, "slices_shuffled_then_whole", shuffled);
    AppendMessage(&dropped, slices[0]);
    AppendMessage(&dropped, slices[1]);
    for (const auto& s : other) AppendMessage(&dropped, s);
    AppendMessage(&dropped, slices[2]);
    Write(dir, "one_cloud_dropped_for_another", dropped);
    auto cut = slices[1];
    cut.pop_back();
    auto flipped = slices[2];
    flipped.back() ^= 0x40;  // the joined cloud's CRC differs
    auto no_slices = slices[0];
    no_slices[32] = no_slices[33] = no_slices[34] = no_slices[35] = 0;  // num_chunks 0
    AppendMessage(&malformed, std::vector<uint8_t>(whole.begin(), whole.begin() + 5));
    AppendMessage(&malformed, io::EncodeModuleStatus(status));
    AppendMessage(&malformed, cut);
    AppendMessage(&malformed, no_slices);
    AppendMessage(&malformed, slices[0]);
    AppendMessage(&malformed, slices[1]);
    AppendMessage(&malformed, flipped);
    AppendMessage(&malformed, slices[3]);
    Write(dir, "malformed", malformed);
  }

  std::vector<uint8_t> huge;  // the issue's 48-byte log: datalen 0x7fffffff
  AppendEvent(&huge, 0, "GRASPFILL_DEPTH", {});
  huge[24] = 0x7f, huge[25] = 0xff, huge[26] = 0xff, huge[27] = 0xff;
  huge.resize(48, 'x');
  Write(root / "lcm_log_reader", "huge_datalen", huge);

  const fs::path ply = root / "ply_reader";
  WriteText(ply, "ascii_cloud",
            "ply\nformat ascii 1.0\ncomment graspfill utime 5\nelement vertex 3\n"
            "property float x\nproperty float y\nproperty float z\nproperty uchar provenance\n"
            "end_header\n0 0 0 0\n0.5 -0.25 1 1\n1e-3 2 3 2\n");
  WriteText(ply, "ascii_mesh",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
            "property double z\nelement face 2\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n");
  WriteText(ply, "cut_header", "ply\nformat ascii 1.0\nobj_info xxxxxxxxxxx");
  const fs::path tmp = fs::temp_directory_path() / "graspfill_make_seeds";
  fs::create_directories(tmp);
  io::WriteCloudPly((tmp / "cloud.ply").string(), cloud);
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  io::WriteMeshPly((tmp / "mesh.ply").string(), mesh);
  fs::copy_file(tmp / "cloud.ply", ply / "binary_cloud", fs::copy_options::overwrite_existing);
  fs::copy_file(tmp / "mesh.ply", ply / "binary_mesh", fs::copy_options::overwrite_existing);
  fs::remove_all(tmp);

  // The planner's mesh: the tetrahedron as a watertight hull with a pose,
  // and as a decimated mesh that is not watertight (one face fewer).
  io::CollisionMeshMessage hull;
  hull.utime = 1700000000002000;
  hull.seq = 3;
  hull.grasp_id = 1;
  hull.T_C_G = state.T_C_G;
  hull.mesh = mesh;
  hull.kind = CollisionMeshKind::kConvexHull;
  hull.watertight = true;
  hull.deviation_m = 0.0004;
  io::CollisionMeshMessage open = hull;
  open.mesh.triangles.pop_back();
  open.kind = CollisionMeshKind::kDecimated;
  open.watertight = false;
  Write(root / "collision_mesh", "hull", io::EncodeCollisionMesh(hull));
  Write(root / "collision_mesh", "open_decimated", io::EncodeCollisionMesh(open));

  const fs::path claw = root / "claw";
  WriteText(claw, "two_links",
            "{\"name\": \"fuzz\", \"links\": [{\"name\": \"palm\", \"mesh\": \"box.ply\"},"
            " {\"name\": \"finger\", \"parent\": \"palm\", \"mesh\": \"box.ply\", \"joint\": {\"type\": "
            "\"prismatic\", \"origin\": {\"xyz\": [0, 0, 0.02]}, \"axis\": [1, 0, 0], \"limits\": "
            "{\"lower\": 0, \"upper\": 0.05}, \"drive\": {\"opening_gain\": 0.5, \"opening_offset\": 0}}}]}");
  WriteText(
      claw, "joint_index",
      "{\"name\": \"fuzz2\", \"links\": [{\"name\": \"palm\", \"mesh\": \"box.ply\", \"mesh_scale\": 1.0},"
      " {\"name\": \"f\", \"parent\": \"palm\", \"mesh\": \"box.ply\", \"joint\": {\"type\": "
      "\"revolute\", \"axis\": [0, 1, 0], \"limits\": {\"lower\": -1, \"upper\": 1}, \"drive\": "
      "{\"joint_index\": 1}}}]}");

  // Repair: flag byte, then float triples (a few points; the target adds
  // its base cylinder when bit 0 is set).
  std::vector<uint8_t> repair = {1};
  for (float v : {0.01f, 0.02f, 0.03f, 1000.0f, 1000.0f, 1000.0f, -0.02f, 0.0f, 0.1f}) {
    uint8_t b[4];
    std::memcpy(b, &v, 4);
    repair.insert(repair.end(), b, b + 4);
  }
  Write(root / "repair", "base_and_strays", repair);
  Write(root / "repair", "base_paper", {3});
  Write(root / "repair", "sparse_base", {9});  // the 800-point base: the Poisson path
  return 0;
}
