// SPDX-License-Identifier: BSD-3-Clause
// Publishes graspfill's messages on an LCM bus (the object cloud and its
// collision mesh for the motion planner, the module's status).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "graspfill/io/collision_mesh_message.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"
#include "sinks/cloud_pacer.hpp"

namespace lcm {
class LCM;
}  // namespace lcm

namespace graspfill::rt {

/// Owns one lcm::LCM instance (hidden behind a Pimpl) and publishes on it.
///
/// Publishing is fire-and-forget: the Publish* methods are on the module's
/// output path and report failure by returning false, never by throwing.
/// On UDP multicast (udpm://, LCM's default) a cloud goes out as
/// object_cloud_chunk_t slices, paced by a thread of the publisher's own
/// (CloudPacer); on other providers (file://, memq://) as one whole
/// object_cloud_t, at once.
/// Thread safety: not thread safe; call from one thread (the sink thread),
/// or serialize calls.
class LcmPublisher {
 public:
  /// @param url LCM provider URL: "" uses LCM's default (the LCM_DEFAULT_URL
  ///   environment variable, else udpm://239.255.76.67:7667?ttl=0);
  ///   "memq://" is in-process (tests: subscribe through lcm_instance()).
  /// @throws std::runtime_error naming the URL if LCM cannot be set up
  ///   (bad URL, no multicast route, ...).
  /// @param pacing  how clouds go out on UDP multicast (ignored elsewhere).
  explicit LcmPublisher(const std::string& url = "", const CloudPacing& pacing = {});
  ~LcmPublisher();
  LcmPublisher(const LcmPublisher&) = delete;
  LcmPublisher& operator=(const LcmPublisher&) = delete;

  /// Publishes `cloud` as object_cloud_t (see io::EncodeObjectCloud), in
  /// paced slices on UDP multicast (queued: the slices go out after this
  /// returns, and before the publisher is destroyed). The first message
  /// too large for a default subscriber's receive buffer
  /// (receive_buffer.hpp) is told to `on_warning`, once.
  /// @return false if encoding (inconsistent cloud) or sending failed (a
  ///   queued cloud's sending: paced_send_failures()).
  bool PublishCloud(const std::string& channel, const ObjectCloud& cloud);
  /// Where PublishCloud's one warning goes (none: not told); called on the
  /// publishing thread.
  void set_on_warning(std::function<void(const std::string&)> on_warning);
  /// Publishes `mesh` as collision_mesh_t (io::EncodeCollisionMesh), one
  /// whole message at once on every provider (not paced; the size warning
  /// as for PublishCloud).
  /// @return false if encoding (an inconsistent mesh) or sending failed.
  bool PublishCollisionMesh(const std::string& channel, const io::CollisionMeshMessage& mesh);
  /// Publishes `status` as module_status_t.
  bool PublishStatus(const std::string& channel, const io::ModuleStatus& status);
  /// Publishes already-encoded bytes (any message type).
  bool PublishRaw(const std::string& channel, const std::vector<uint8_t>& bytes);

  /// Waits until the queued clouds' slices went out (true), or
  /// `timeout_ms` (false); true at once where clouds are not paced.
  bool FlushClouds(int timeout_ms);
  /// Slices LCM did not take, and queued clouds dropped for newer ones.
  int64_t paced_send_failures() const;
  int64_t paced_clouds_dropped() const;

  /// The URL this publisher was created with ("" = LCM's default).
  const std::string& url() const;
  /// The underlying LCM instance, for callers that also subscribe on the
  /// same provider (with memq:// only the same instance receives). Owned by
  /// this publisher.
  lcm::LCM* lcm_instance();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::rt
