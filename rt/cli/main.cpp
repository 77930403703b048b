// SPDX-License-Identifier: BSD-3-Clause
// graspfill: grasp-reconstruction module and its tools.
#include <malloc.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "commands.hpp"
#include "error_text.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/io/messages.hpp"
#include "progress.hpp"
#include "unknown_option.hpp"

namespace {

// Open3D's TSDF integration asks OpenMP for a thread per physical core per
// voxel block; on 2 busy cores that is 15-30x slower than one thread (see
// tsdf_fusion.hpp). The pipeline and the repair set their own count per
// call (compute.num_threads, --num-threads; default 1); everything else
// the CLI runs on its main thread (collision meshes, eval, bench's own
// Open3D integration) stays on that thread too. The calling thread's
// OpenMP settings, not OMP_THREAD_LIMIT: no re-execution, and a limit the
// user set in the environment still holds.
void OneOpenMpThreadOnMain() { graspfill::SetOpenMpThreads(1); }

// glibc gives every block over 128 KiB back to the kernel when it is freed,
// so each repair (kNN tables and grids of a few MB on a 20k-point cloud)
// page-faults its memory in again: on this project's 2-core VMs ~15% of a
// repair's time went to page faults and zeroing. Blocks up to 32 MiB now
// stay in the heap for the next repair (RSS stays at its high-water mark).
// The shape zoo's repairs with evidence (bench repair --pipeline, one run
// each): 1,850 ms -> 1,643 ms summed over 15 objects.
void KeepFreedMemoryForReuse() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
}

void PrintUsage() {
  std::fprintf(stderr,
               "usage: graspfill <command> [options]\n"
               "commands:\n"
               "  synth   write a synthetic recording (LCM log) and its ground truth\n"
               "  replay  replay a recording through the pipeline, repair and write the cloud\n"
               "  eval    compare a predicted cloud with the ground truth\n"
               "  bench   per-frame timings beside Open3D's integration alone; `bench repair`: Tables 1-3;\n"
               "          `bench live`: the live module's latency and drops at 1x, 2x, 4x\n"
               "  demo    replay the bundled recording and evaluate it\n"
               "  live    OpenNI2 camera + gripper states over LCM -> object cloud over LCM\n"
               "  oni-record  an OpenNI2 device's depth into an .oni file (OpenNI2's recorder)\n"
               "  repair  fill the claw holes and the unseen top of an object cloud\n"
               "  claw    write a claw (built-in, description or URDF) posed at an opening as PLY\n"
               "  config  the rig config: --dump-defaults (documented YAML), --check FILE\n"
               "  view    a picture (PNG) of clouds in their provenance colours, before / after\n"
               "run `graspfill <command> --help` for the command's options\n"
               "options of every command: --quiet (no progress line on a terminal)\n"
               "graspfill --version: the version\n");
}

}  // namespace

int main(int argc, char** argv) {
  OneOpenMpThreadOnMain();
  KeepFreedMemoryForReuse();
  if (argc < 2) {
    PrintUsage();
    return 2;
  }
  // Piped or redirected, stdout would be written in 4 KiB blocks: a
  // command's rows (bench repair's cases) would come at its end, not as
  // they are made.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const std::string command = argv[1];
  if (command == "--version") {
    std::printf("%s\n", graspfill::io::SoftwareVersion().c_str());
    return 0;
  }
  // --quiet is every command's: taken off before the command reads its own.
  graspfill::cli::Args args;
  for (int i = 2; i < argc; ++i) {
    if (std::string(argv[i]) == "--quiet")
      graspfill::cli::ProgressQuiet() = true;
    else
      args.emplace_back(argv[i]);
  }
  try {
    if (command == "synth") return graspfill::cli::RunSynth(args);
    if (command == "replay") return graspfill::cli::RunReplay(args);
    if (command == "eval") return graspfill::cli::RunEval(args);
    if (command == "bench") return graspfill::cli::RunBench(args);
    if (command == "demo") return graspfill::cli::RunDemo(args);
    if (command == "live") return graspfill::cli::RunLive(args);
    if (command == "oni-record") return graspfill::cli::RunOniRecord(args);
    if (command == "repair") return graspfill::cli::RunRepair(args);
    if (command == "claw") return graspfill::cli::RunClaw(args);
    if (command == "config") return graspfill::cli::RunConfig(args);
    if (command == "view") return graspfill::cli::RunView(args);
    if (command == "--help" || command == "-h" || command == "help") {
      PrintUsage();
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill %s: error: %s\n", command.c_str(), graspfill::cli::ErrorText(e).c_str());
    return 1;
  }
  const std::string near = graspfill::cli::Nearest(
      command,
      {"synth", "replay", "eval", "bench", "demo", "live", "oni-record", "repair", "claw", "config", "view"});
  std::fprintf(stderr, "graspfill: unknown command '%s'%s\n", command.c_str(),
               near.empty() ? "" : (" (did you mean " + near + "?)").c_str());
  PrintUsage();
  return 2;
}
