// SPDX-License-Identifier: BSD-3-Clause
// The claws of session descriptions, checked off the bus's and the status's
// threads. Building a claw may take seconds (a URDF of thousands of links),
// so it runs on a thread of its own: each description's claw is built there
// and compared with the claw in use, and the verdict is remembered by the
// claw's identity (kind, name and a hash of its text), so that a
// description sent again costs a lookup on the caller's thread.
//
// Before the claw in use is set, the first description whose claw was
// built is kept (with the claw) for the session to start with; the others
// are compared once it is set.
//
// Threads: Submit from any thread (the bus's receive thread); it never
// waits for a build. The callbacks run on the checker's thread, except an
// unloadable verdict already known, which Submit reports on its caller's.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/io/messages.hpp"

namespace graspfill::rt {

/// A session description and the claw built from it.
struct DescribedClaw {
  io::SessionDescription session;
  claw::ClawModel claw;
};

class SessionClawChecker {
 public:
  /// Builds the claw a description gives; throws (std::exception) naming
  /// the problem when it cannot.
  using Build = std::function<claw::ClawModel(const io::SessionDescription&)>;
  /// Whether two claws are the same claw, whichever way they were given.
  using Same = std::function<bool(const claw::ClawModel&, const claw::ClawModel&)>;
  struct Callbacks {
    /// The description's claw could not be built (`why`: Build's error):
    /// for every such description (a repeated one reported from the cache).
    std::function<void(const io::SessionDescription&, const std::string& why)> on_unloadable;
    /// The description's claw is not the claw in use: once per distinct
    /// claw.
    std::function<void(const io::SessionDescription&)> on_other_claw;
  };

  /// Starts the checker's thread.
  SessionClawChecker(Build build, Same same, Callbacks callbacks);
  /// Drops what waits and joins the thread (after the build under way).
  ~SessionClawChecker();
  SessionClawChecker(const SessionClawChecker&) = delete;
  SessionClawChecker& operator=(const SessionClawChecker&) = delete;

  /// Hands a description over to be checked; never waits for a build. A
  /// claw already judged, the claw in use, or one waiting or being built
  /// is not built again. At most kMaxWaiting descriptions wait: beyond,
  /// the oldest waiting one is dropped (counted in dropped()).
  void Submit(const io::SessionDescription& session);

  /// The claw the session runs with and the description that gives it
  /// (its identity: a description of the same claw is not warned about).
  /// The descriptions built before are compared with it now.
  void SetClawInUse(const claw::ClawModel& claw, const io::SessionDescription& described);

  /// The first description whose claw was built before SetClawInUse.
  std::optional<DescribedClaw> FirstBuilt() const;

  /// No description waits or is being checked.
  bool Idle() const;
  /// Waits until Idle or `timeout`; true if idle.
  bool WaitIdle(std::chrono::milliseconds timeout) const;

  /// Descriptions dropped unchecked because kMaxWaiting waited already.
  int64_t dropped() const;

  static constexpr size_t kMaxWaiting = 4;
  /// Verdicts remembered (the oldest forgotten beyond).
  static constexpr size_t kMaxVerdicts = 256;

 private:
  enum class Verdict { kSame, kOther, kUnloadable };
  struct Job {
    io::SessionDescription session;
    std::string key;
    std::shared_ptr<const claw::ClawModel> built;  // set: compare only
  };
  static std::string KeyOf(const io::SessionDescription& session);
  void Loop();
  void Remember(const std::string& key, Verdict verdict, const std::string& why);

  Build build_;
  Same same_;
  Callbacks callbacks_;

  mutable std::mutex mutex_;  // everything below but the thread
  mutable std::condition_variable changed_;
  std::deque<Job> waiting_;
  std::string key_in_progress_;
  bool busy_{false};
  bool stop_{false};
  int64_t dropped_{0};
  std::map<std::string, std::pair<Verdict, std::string>> verdicts_;
  std::deque<std::string> verdict_order_;  // for forgetting the oldest
  std::shared_ptr<const claw::ClawModel> in_use_;
  std::string in_use_key_;
  std::optional<DescribedClaw> first_built_;
  std::string first_built_key_;
  std::vector<Job> built_before_;  // distinct, compared at SetClawInUse
  std::thread thread_;             // last: started once the rest is made
};

}  // namespace graspfill::rt
