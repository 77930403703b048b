// SPDX-License-Identifier: BSD-3-Clause
// graspfill demo: the bundled default recording through `replay`, then the
// result against the recording's ground truth through `eval`.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "commands.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "graspfill/io/output_path.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {

int RunDemo(const Args& args) {
  std::string out_dir = DefaultDemoDir().string();
  bool own_dir = true;  // the demo's own folder is rewritten each run
  bool force = false;
  Args replay_extra;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::printf(
          "usage: graspfill demo [-o DIR] [--force] [--lcm-url URL] [--no-publish]\n"
          "  replays the bundled recording, writes DIR/cloud.ply, publishes the cloud\n"
          "  over LCM and evaluates it against the ground truth\n"
          "  recording: %s/replay/default/recording.lcmlog\n"
          "             (the data folder: $GRASPFILL_DATA_DIR, else the executable's\n"
          "             ../share/graspfill)\n"
          "  DIR:       default %s\n"
          "             (the demo's own folder, rewritten each run); a DIR\n"
          "             given with -o is not overwritten without --force\n",
          DataDir().c_str(), out_dir.c_str());
      return 0;
    }
    if (args[i] == "-o" && i + 1 < args.size()) {
      out_dir = args[++i];
      own_dir = false;
    } else if (args[i] == "--force") {
      force = true;
    } else if (args[i] == "--lcm-url" && i + 1 < args.size()) {
      replay_extra.push_back(args[i]);
      replay_extra.push_back(args[++i]);
    } else if (args[i] == "--no-publish") {
      replay_extra.push_back(args[i]);
    } else {
      std::fprintf(stderr, "graspfill demo: %s\n",
                   BadOptionText(args[i], "-o DIR --force --lcm-url URL --no-publish").c_str());
      return 2;
    }
  }
  const std::string recording = BundledRecordingDir().string();
  const std::string cloud = out_dir + "/cloud.ply";
  const bool overwrite = force || own_dir;
  try {
    io::PrepareOutputDir(out_dir);
    io::CheckOutputFile(cloud, overwrite);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill demo: %s\n", ErrorText(e).c_str());
    return 1;
  }
  Args replay = {recording + "/recording.lcmlog", "-o", cloud};
  if (overwrite) replay.push_back("--force");
  replay.insert(replay.end(), replay_extra.begin(), replay_extra.end());
  std::printf("== graspfill replay %s/recording.lcmlog\n", recording.c_str());
  std::fflush(stdout);
  if (const int rc = RunReplay(replay); rc != 0) return rc;
  std::printf("== graspfill eval %s %s/gt_cloud.ply\n", cloud.c_str(), recording.c_str());
  std::fflush(stdout);
  return RunEval({cloud, recording + "/gt_cloud.ply"});
}

}  // namespace graspfill::cli
