// SPDX-License-Identifier: BSD-3-Clause
// OpenNI2Source in a build without OpenNI2 (GRASPFILL_WITH_OPENNI2=OFF, the
// default as a part of another project where libopenni2 is not installed):
// construction throws, everything else in the runtime works.
#include <stdexcept>
#include <string>

#include "sources/openni2_source.hpp"

namespace graspfill::rt {

class OpenNI2Source::Impl {};

OpenNI2Source::OpenNI2Source(const Config& config) {
  const std::string what = config.uri.empty() ? "any device" : "'" + config.uri + "'";
  throw std::runtime_error("OpenNI2: cannot open " + what +
                           ": graspfill was built without OpenNI2 "
                           "(GRASPFILL_WITH_OPENNI2=OFF)");
}

OpenNI2Source::~OpenNI2Source() = default;

// Unreachable: no OpenNI2Source is ever constructed.
FrameResult OpenNI2Source::Next(DepthFrame*) { return FrameResult::kEndOfStream; }
FrameResult OpenNI2Source::Next(SourceEvent*) { return FrameResult::kEndOfStream; }

const std::string& OpenNI2Source::last_error() const {
  static const std::string kNone;
  return kNone;
}

bool OpenNI2Source::is_recording() const { return false; }
bool OpenNI2Source::paced_by_reader() const { return false; }
std::string OpenNI2Source::mode_text() const { return ""; }
void OpenNI2Source::StartRecording(const std::string&) {}

}  // namespace graspfill::rt
