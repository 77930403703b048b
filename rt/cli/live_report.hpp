// SPDX-License-Identifier: BSD-3-Clause
// What `graspfill live` tells once the session is over
// (rt/module/live_session.hpp): frames, latency, skips, the recording and
// the repair, as lines for people.
#pragma once

#include <string>

#include "graspfill/io/channel_names.hpp"
#include "module/live_session.hpp"

namespace graspfill::cli {

/// Prints the summary on stdout (a recording that stopped early also on
/// stderr); returns live's exit code: 1 if the recording stopped early,
/// else 0. `record_path`: --record's, "" = none.
int PrintLiveSummary(const rt::LiveSessionSummary& summary, const io::ChannelNames& channels,
                     const std::string& record_path);

}  // namespace graspfill::cli
