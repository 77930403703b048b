// SPDX-License-Identifier: BSD-3-Clause
#include "module/session_claw_checker.hpp"

#include <cstdio>
#include <exception>
#include <utility>

namespace graspfill::rt {

SessionClawChecker::SessionClawChecker(Build build, Same same, Callbacks callbacks)
    : build_(std::move(build)), same_(std::move(same)), callbacks_(std::move(callbacks)) {
  thread_ = std::thread([this] { Loop(); });
}

SessionClawChecker::~SessionClawChecker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    waiting_.clear();
  }
  changed_.notify_all();
  thread_.join();
}

std::string SessionClawChecker::KeyOf(const io::SessionDescription& session) {
  // The claw's identity: what builds it. A hash stands for the text (which
  // may be megabytes); a collision would only spare a warning.
  char hash[48];
  std::snprintf(hash, sizeof(hash), "%zx:%zu", std::hash<std::string>{}(session.claw_text),
                session.claw_text.size());
  return std::to_string(static_cast<int>(session.claw_kind)) + "\n" + session.claw_name + "\n" + hash;
}

void SessionClawChecker::Submit(const io::SessionDescription& session) {
  std::string key = KeyOf(session);
  std::string unloadable_why;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_ || (in_use_ && key == in_use_key_)) return;
    const auto known = verdicts_.find(key);
    if (known == verdicts_.end()) {
      if (busy_ && key == key_in_progress_) return;
      if (!in_use_ && first_built_ && key == first_built_key_) return;
      for (const Job& job : waiting_) {
        if (job.key == key) return;
      }
      for (const Job& job : built_before_) {
        if (job.key == key) return;
      }
      if (waiting_.size() >= kMaxWaiting) {
        waiting_.pop_front();
        ++dropped_;
      }
      waiting_.push_back(Job{session, std::move(key), nullptr});
      changed_.notify_all();
      return;
    }
    if (known->second.first != Verdict::kUnloadable) return;  // warned about once
    unloadable_why = known->second.second;
  }
  if (callbacks_.on_unloadable) callbacks_.on_unloadable(session, unloadable_why);
}

void SessionClawChecker::SetClawInUse(const claw::ClawModel& claw, const io::SessionDescription& described) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_use_ = std::make_shared<const claw::ClawModel>(claw);
    in_use_key_ = KeyOf(described);
    // Verdicts of sameness were against no claw or another: judged anew.
    std::deque<std::string> order;
    for (const std::string& key : verdict_order_) {
      const auto it = verdicts_.find(key);
      if (it == verdicts_.end()) continue;
      if (it->second.first == Verdict::kUnloadable) {
        order.push_back(key);
      } else {
        verdicts_.erase(it);
      }
    }
    verdict_order_ = std::move(order);
    if (first_built_ && first_built_key_ != in_use_key_) {
      waiting_.push_back(Job{first_built_->session, first_built_key_,
                             std::make_shared<const claw::ClawModel>(first_built_->claw)});
    }
    for (Job& job : built_before_) {
      if (job.key != in_use_key_) waiting_.push_back(std::move(job));
    }
    built_before_.clear();
  }
  changed_.notify_all();
}

std::optional<DescribedClaw> SessionClawChecker::FirstBuilt() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return first_built_;
}

bool SessionClawChecker::Idle() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_.empty() && !busy_;
}

bool SessionClawChecker::WaitIdle(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, timeout, [this] { return waiting_.empty() && !busy_; });
}

int64_t SessionClawChecker::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

void SessionClawChecker::Remember(const std::string& key, Verdict verdict, const std::string& why) {
  if (!verdicts_.emplace(key, std::make_pair(verdict, why)).second) return;
  verdict_order_.push_back(key);
  while (verdicts_.size() > kMaxVerdicts && !verdict_order_.empty()) {
    verdicts_.erase(verdict_order_.front());
    verdict_order_.pop_front();
  }
}

void SessionClawChecker::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || !waiting_.empty(); });
    if (stop_) return;
    Job job = std::move(waiting_.front());
    waiting_.pop_front();
    key_in_progress_ = job.key;
    busy_ = true;
    lock.unlock();

    std::shared_ptr<const claw::ClawModel> claw = job.built;
    std::string why;
    if (!claw) {
      try {
        claw = std::make_shared<const claw::ClawModel>(build_(job.session));
      } catch (const std::exception& e) {
        why = e.what();
      } catch (...) {
        why = "unknown error";
      }
      if (!claw && why.empty()) why = "unknown error";
    }
    lock.lock();
    const std::shared_ptr<const claw::ClawModel> in_use = in_use_;
    const std::string in_use_key = in_use_key_;
    if (!claw) {
      Remember(job.key, Verdict::kUnloadable, why);
    } else if (!in_use) {  // kept until the claw in use is known
      if (!first_built_) {
        first_built_ = DescribedClaw{job.session, *claw};
        first_built_key_ = job.key;
      } else if (built_before_.size() < kMaxWaiting) {
        built_before_.push_back(Job{job.session, job.key, claw});
      }
    }
    lock.unlock();

    bool other = false;
    if (claw && in_use) {
      try {
        other = job.key != in_use_key && (!same_ || !same_(*in_use, *claw));
      } catch (const std::exception&) {
        other = true;
      }
      lock.lock();
      Remember(job.key, other ? Verdict::kOther : Verdict::kSame, "");
      lock.unlock();
    }
    if (!claw && callbacks_.on_unloadable) callbacks_.on_unloadable(job.session, why);
    if (other && callbacks_.on_other_claw) callbacks_.on_other_claw(job.session);

    lock.lock();
    busy_ = false;
    key_in_progress_.clear();
    changed_.notify_all();
  }
}

}  // namespace graspfill::rt
