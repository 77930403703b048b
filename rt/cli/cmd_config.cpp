// SPDX-License-Identifier: BSD-3-Clause
// graspfill config: the rig config file (rt/config/rig_config.hpp).
//   --dump-defaults [-o FILE [--force]]  every field with its default and
//                                        what it means, as YAML
//   --check FILE                         parse FILE strictly; print it back
//                                        with the defaults filled in
#include <cstdio>
#include <exception>
#include <string>

#include "commands.hpp"
#include "config/rig_config.hpp"
#include "error_text.hpp"
#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/output_path.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kConfigUsage =
    "usage: graspfill config --dump-defaults [-o FILE [--force]]\n"
    "       graspfill config --check FILE\n"
    "  --dump-defaults   print the rig config with every default, documented (YAML);\n"
    "                    `replay --config FILE` and `live --config FILE` read it\n"
    "  -o, --output FILE write it to FILE instead (atomically; not over an existing\n"
    "                    file without --force)\n"
    "  --check FILE      read FILE as `--config FILE` does: exit 0 and print the config\n"
    "                    it gives (defaults filled in), or exit 2 naming the bad field\n"
    "example: graspfill config --dump-defaults -o rig.yaml\n";

}  // namespace

int RunConfig(const Args& args) {
  bool dump = false, force = false;
  std::string output, check;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
        return args[++i];
      };
      if (a == "--help" || a == "-h") {
        std::fputs(kConfigUsage, stdout);
        return 0;
      } else if (a == "--dump-defaults") {
        dump = true;
      } else if (a == "-o" || a == "--output") {
        output = value();
      } else if (a == "--force") {
        force = true;
      } else if (a == "--check") {
        check = value();
      } else {
        throw BadOption(a, kConfigUsage);
      }
    }
    if (dump == !check.empty()) throw UsageError("need --dump-defaults or --check FILE");
    if (!output.empty() && !dump) throw UsageError("-o goes with --dump-defaults");
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill config: %s\n%s", e.what(), kConfigUsage);
    return 2;
  }
  if (!check.empty()) {
    try {
      const rt::RigConfig config = rt::LoadRigConfig(check);
      std::fputs(rt::DumpRigConfig(config).c_str(), stdout);
      return 0;
    } catch (const rt::ConfigError& e) {
      std::fprintf(stderr, "graspfill config: %s\n", e.what());
      return 2;
    }
  }
  const std::string text = rt::DumpRigConfig(rt::RigConfig{});
  if (output.empty()) {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  try {
    io::CheckOutputFile(output, force);
    io::WriteFileAtomically(output, text, "cannot write config", io::ReplaceIf(force));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill config: %s\n", ErrorText(e).c_str());
    return 1;
  }
  std::printf("rig config defaults -> %s\n", output.c_str());
  return 0;
}

}  // namespace graspfill::cli
