// SPDX-License-Identifier: BSD-3-Clause
// Sub-commands of the `graspfill` CLI, one file each. Each takes the
// arguments after its name and returns the process exit code: 0 on success,
// 1 on bad input or a failed run (with a message on stderr), 2 on usage error.
#pragma once

#include <string>
#include <vector>

namespace graspfill::cli {

using Args = std::vector<std::string>;

/// `graspfill live`'s heap reserve [MB] (rt/module/process_memory.hpp),
/// which `bench live` runs with too: a first grasp of a household object
/// takes ~140 MB.
constexpr int kLiveHeapReserveMb = 256;

int RunSynth(const Args& args);                // cmd_synth.cpp
int RunReplay(const Args& args);               // cmd_replay.cpp
int RunEval(const Args& args);                 // cmd_eval.cpp
int RunBench(const Args& args);                // cmd_bench.cpp
int RunDemo(const Args& args);                 // cmd_demo.cpp
int RunLive(const Args& args);                 // cmd_live.cpp
int RunOniRecord(const Args& args);            // cmd_oni_record.cpp
int RunRepair(const Args& args);               // cmd_repair.cpp
int RunBenchRepair(const Args& args);          // cmd_bench_repair.cpp
int RunBenchRepairPipeline(const Args& args);  // cmd_bench_pipeline.cpp
int RunBenchRepairObjects(const Args& args);   // cmd_bench_objects.cpp
int RunBenchLive(const Args& args);            // cmd_bench_live.cpp
int RunClaw(const Args& args);                 // cmd_claw.cpp
int RunConfig(const Args& args);               // cmd_config.cpp
int RunView(const Args& args);                 // cmd_view.cpp

}  // namespace graspfill::cli
