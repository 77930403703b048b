// SPDX-License-Identifier: BSD-3-Clause
// A planner's side of graspfill, in C++: subscribes to the object clouds (or,
// with --meshes, their collision meshes) and prints a summary of each. Needs
// LCM and graspfill's message decoders (target graspfill::io): on LCM's UDP
// multicast each cloud comes as one-datagram slices (object_cloud_chunk_t.lcm),
// which io::CloudChunkAssembler joins (a log's whole object_cloud_t passes
// through it); the points travel packed (object_cloud_t.lcm), and
// io::DecodeObjectCloud unpacks and checks them. A collision mesh comes
// whole (collision_mesh_t.lcm): io::DecodeCollisionMesh checks it (every
// index within the vertices) before a planner builds a collision object of
// it (docs/planner-bindings.md).
//
// usage: object_cloud_subscriber [URL] [--meshes] [--channel NAME] [--count N] [--timeout-s S]
//   URL   LCM's URL (default: LCM_DEFAULT_URL, else UDP multicast); a bus log
//         recorded with lcm-logger or graspfill plays as "file://LOG?speed=0"
// Prints per cloud:
//   seq=S utime=U grasp=G final=F points=N observed=A surface=B symmetry=C holes=H unobserved=U trusted=T
//   (T: the added points the repair stands behind, confidence above 0.5)
// and per mesh (--meshes; channel GRASPFILL_COLLISION_MESH unless --channel):
//   mesh seq=S utime=U grasp=G kind=K watertight=W vertices=V triangles=T deviation_mm=D
// Exit: 0 once N messages (default 1) are received; 1 on a usage error, an
// undecodable message, the end of a log or S seconds (default 10) without a
// message before that.
#include <lcm/lcm-cpp.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/collision_mesh_message.hpp"
#include "graspfill/io/messages.hpp"

namespace {

class Printer {
 public:
  // Called on the thread that calls handle(): decodes, prints and counts.
  void OnMessage(const lcm::ReceiveBuffer* buffer, const std::string&) {
    using Result = graspfill::io::CloudChunkAssembler::Result;
    std::string error;
    const Result joined = slices_.Add(buffer->data, buffer->data_size, &error);
    if (joined == Result::kPending || joined == Result::kRepeat) return;  // more slices to come
    const std::vector<uint8_t>& bytes = slices_.cloud();
    if (joined != Result::kComplete ||
        !graspfill::io::DecodeObjectCloud(bytes.data(), bytes.size(), &cloud_, &error)) {
      std::fprintf(stderr, "object_cloud_subscriber: skipping a message: %s\n", error.c_str());
      return;
    }
    std::array<long long, 3> by_provenance{0, 0, 0};
    for (const graspfill::Provenance p : cloud_.provenance) ++by_provenance[static_cast<size_t>(p)];
    // Holes whose inside nothing is known of (an open mouth): keep clear.
    int unobserved = 0;
    for (const graspfill::HoleSummary& h : cloud_.holes) unobserved += h.unobserved ? 1 : 0;
    // Added points more likely right than not; the rest of the added ones
    // (a lid no view saw) are a guess, which the safe bound covers.
    long long trusted = 0;
    for (size_t i = 0; i < cloud_.size(); ++i) {
      trusted += cloud_.provenance[i] != graspfill::Provenance::kObserved && cloud_.confidence[i] > 0.5f;
    }
    std::printf(
        "seq=%lld utime=%lld grasp=%lld final=%d points=%zu observed=%lld "
        "surface=%lld symmetry=%lld holes=%zu unobserved=%d trusted=%lld\n",
        static_cast<long long>(cloud_.seq), static_cast<long long>(cloud_.utime),
        static_cast<long long>(cloud_.grasp_id), cloud_.is_final ? 1 : 0, cloud_.points_G.size(),
        by_provenance[static_cast<size_t>(graspfill::Provenance::kObserved)],
        by_provenance[static_cast<size_t>(graspfill::Provenance::kSurface)],
        by_provenance[static_cast<size_t>(graspfill::Provenance::kSymmetry)], cloud_.holes.size(), unobserved,
        trusted);
    std::fflush(stdout);
    ++received;
  }
  void OnMesh(const lcm::ReceiveBuffer* buffer, const std::string&) {
    std::string error;
    if (!graspfill::io::DecodeCollisionMesh(buffer->data, buffer->data_size, &mesh_, &error)) {
      std::fprintf(stderr, "object_cloud_subscriber: skipping a message: %s\n", error.c_str());
      return;
    }
    // A planner adds mesh_.mesh as a collision object attached to the
    // gripper frame (mesh_.frame_name), trusting its inside only when
    // watertight, padded by deviation_m.
    std::printf(
        "mesh seq=%lld utime=%lld grasp=%lld kind=%s watertight=%d vertices=%zu "
        "triangles=%zu deviation_mm=%.3f\n",
        static_cast<long long>(mesh_.seq), static_cast<long long>(mesh_.utime),
        static_cast<long long>(mesh_.grasp_id),
        mesh_.kind == graspfill::CollisionMeshKind::kConvexHull ? "convex_hull" : "decimated",
        mesh_.watertight ? 1 : 0, mesh_.mesh.vertices.size(), mesh_.mesh.triangles.size(),
        mesh_.deviation_m * 1e3);
    std::fflush(stdout);
    ++received;
  }
  int received{0};

 private:
  graspfill::io::CloudChunkAssembler slices_;
  graspfill::ObjectCloud cloud_;  // reused: no allocation per cloud once warm
  graspfill::io::CollisionMeshMessage mesh_;
};

}  // namespace

int main(int argc, char** argv) {
  std::string url, channel;
  bool meshes = false;
  int count = 1;
  int timeout_s = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--channel" && has_value)
      channel = argv[++i];
    else if (a == "--meshes")
      meshes = true;
    else if (a == "--count" && has_value)
      count = std::atoi(argv[++i]);
    else if (a == "--timeout-s" && has_value)
      timeout_s = std::atoi(argv[++i]);
    else if (url.empty() && !a.empty() && a[0] != '-')
      url = a;
    else {
      std::fprintf(stderr, "usage: %s [URL] [--meshes] [--channel NAME] [--count N] [--timeout-s S]\n",
                   argv[0]);
      return 1;
    }
  }
  if (count < 1 || timeout_s < 1) {
    std::fprintf(stderr, "object_cloud_subscriber: --count and --timeout-s must be >= 1\n");
    return 1;
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "object_cloud_subscriber: cannot open LCM at '%s'\n", url.c_str());
    return 1;
  }
  if (channel.empty()) channel = meshes ? "GRASPFILL_COLLISION_MESH" : "GRASPFILL_OBJECT_CLOUD";
  const char* what = meshes ? "mesh" : "cloud";
  const char* whats = meshes ? "meshes" : "clouds";
  Printer printer;
  lcm.subscribe(channel, meshes ? &Printer::OnMesh : &Printer::OnMessage, &printer);
  while (printer.received < count) {
    const int status = lcm.handleTimeout(timeout_s * 1000);
    if (status == 0) {
      std::fprintf(stderr, "object_cloud_subscriber: no %s on %s for %d s\n", what, channel.c_str(),
                   timeout_s);
      return 1;
    }
    if (status < 0) {  // a log's end, or the bus failed
      std::fprintf(stderr, "object_cloud_subscriber: %d of %d %s, then LCM ended\n", printer.received, count,
                   whats);
      return 1;
    }
  }
  return 0;
}
