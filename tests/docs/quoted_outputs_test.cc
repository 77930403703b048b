// SPDX-License-Identifier: BSD-3-Clause
// The outputs the README and docs/ quote come from the product: a quoted
// block is marked in the Markdown with `<!-- output: NAME -->` on the line
// before its fence, and NAME's case below runs the commands that print it.
// The quoted lines must appear in what the commands print, in order and
// exactly (trailing spaces aside; the output may hold more lines). No
// number is normalised: every case is deterministic. Also checked: every
// marker has a case and every case a marker; a fenced block without a
// marker holds no line that reads like the CLI's own output
// ("graspfill <command>: ..."); and the model size the README quotes is the
// size of the message replay publishes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "graspfill/io/lcm_log_reader.hpp"

namespace graspfill {
namespace {

namespace fs = std::filesystem;
using testing::RunShell;
using testing::ScratchDir;

struct Step {
  std::map<std::string, std::string> files;  ///< written into the scratch folder first
  std::string command;                       ///< shell, in the scratch folder; {cli}, {subscriber}, {source}
};

// The cases, by marker name.
const std::map<std::string, std::vector<Step>>& Cases() {
  static const std::map<std::string, std::vector<Step>> cases = {
      {"rig-config-errors",
       {{{{"rig.yaml",
           "camera:\n  device: \"\"\nrobot:\n  clock_offset_s: 0\ntsdf:\n"
           "  sdf_trunc_voxels: 4\n  voxel_m: 0.002mm\n"}},
         "{cli} replay {source}/replay/default/recording.lcmlog -o out.ply --config rig.yaml"},
        {{{"rig.yaml", "robot:\n  max_pose_gap_s: 0.05\n  clock_ofset_s: 0.02\n"}},
         "{cli} replay {source}/replay/default/recording.lcmlog -o out.ply --config rig.yaml"}}},
      {"version", {{{}, "{cli} --version"}}},
      {"bundled-model-on-the-bus",
       {{{},
         "{cli} replay {source}/replay/default/recording.lcmlog -o cloud.ply "
         "--lcm-url 'file://'$PWD'/bus.lcmlog?mode=w' >/dev/null && "
         "{subscriber} 'file://'$PWD'/bus.lcmlog?speed=0'"}}},
  };
  return cases;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

struct Quote {
  std::string file;
  int line{0};       ///< of the marker
  std::string name;  ///< the case; "" for an unmarked block
  std::vector<std::string> lines;
};

// Every fenced block of the README and docs/ (measurements included),
// with the marker before it, if any.
std::vector<Quote> FencedBlocks() {
  std::vector<fs::path> files = {fs::path(GRASPFILL_SOURCE_DIR) / "README.md"};
  for (const auto& e : fs::recursive_directory_iterator(fs::path(GRASPFILL_SOURCE_DIR) / "docs")) {
    if (e.path().extension() == ".md") files.push_back(e.path());
  }
  const std::regex marker(R"(^<!-- output: ([a-z0-9-]+) -->$)");
  std::vector<Quote> quotes;
  for (const fs::path& path : files) {
    const std::vector<std::string> lines = Lines(ReadText(path));
    std::string pending;
    int pending_line = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
      std::smatch m;
      if (std::regex_match(lines[i], m, marker)) {
        pending = m[1];
        pending_line = static_cast<int>(i) + 1;
        continue;
      }
      if (lines[i].rfind("```", 0) != 0) {
        if (!lines[i].empty()) pending.clear();  // a marker names the very next block
        continue;
      }
      Quote q;
      q.file = fs::relative(path, GRASPFILL_SOURCE_DIR).string();
      q.line = pending.empty() ? static_cast<int>(i) + 1 : pending_line;
      q.name = pending;
      for (++i; i < lines.size() && lines[i].rfind("```", 0) != 0; ++i) q.lines.push_back(lines[i]);
      quotes.push_back(q);
      pending.clear();
    }
  }
  return quotes;
}

std::string RunCase(const std::string& name) {
  const std::string dir = ScratchDir("quoted_" + name);
  std::string output;
  for (const Step& step : Cases().at(name)) {
    for (const auto& [file, text] : step.files) std::ofstream(dir + "/" + file) << text;
    std::string command = Replace(step.command, "{cli}", GRASPFILL_CLI);
    command = Replace(command, "{subscriber}", EXAMPLE_CPP_SUBSCRIBER);
    command = Replace(command, "{source}", GRASPFILL_SOURCE_DIR);
    output += RunShell("cd '" + dir + "' && LCM_DEFAULT_URL=memq:// " + command + " 2>&1").output;
  }
  return output;
}

TEST(QuotedOutputs, EveryMarkerHasACaseAndEveryCaseAMarker) {
  std::set<std::string> marked;
  for (const Quote& q : FencedBlocks()) {
    if (q.name.empty()) continue;
    EXPECT_TRUE(Cases().count(q.name)) << q.file << ":" << q.line << ": no case '" << q.name << "'";
    marked.insert(q.name);
  }
  for (const auto& [name, steps] : Cases()) {
    EXPECT_TRUE(marked.count(name)) << "case '" << name << "' quoted nowhere";
  }
}

TEST(QuotedOutputs, UnmarkedBlocksQuoteNoCliOutput) {
  // The CLI's messages start "graspfill <command>: "; a command line
  // ("graspfill replay LOG ...") does not.
  const std::regex cli_output(R"(^(build/bin/)?graspfill [a-z-]+: .*)");
  for (const Quote& q : FencedBlocks()) {
    if (!q.name.empty()) continue;
    for (const std::string& line : q.lines) {
      EXPECT_FALSE(std::regex_match(line, cli_output))
          << q.file << ":" << q.line << ": quotes the CLI's output without an "
          << "<!-- output: NAME --> marker: " << line;
    }
  }
}

TEST(QuotedOutputs, QuotedLinesAreWhatTheCommandsPrint) {
  for (const Quote& q : FencedBlocks()) {
    if (q.name.empty() || !Cases().count(q.name)) continue;
    SCOPED_TRACE(q.file + ":" + std::to_string(q.line) + " (" + q.name + ")");
    const std::string output = RunCase(q.name);
    const std::vector<std::string> printed = Lines(output);
    size_t at = 0;
    for (const std::string& quoted : q.lines) {
      while (at < printed.size() && printed[at] != quoted) ++at;
      EXPECT_LT(at, printed.size()) << "quoted, not printed (or not in this order): " << quoted
                                    << "\nprinted:\n"
                                    << output;
      if (at == printed.size()) break;
      ++at;
    }
  }
}

// "the bundled recording's model is N bytes": the message replay publishes.
TEST(QuotedOutputs, ReadmeModelSizeIsThePublishedMessagesSize) {
  const std::string readme = ReadText(fs::path(GRASPFILL_SOURCE_DIR) / "README.md");
  std::smatch m;
  const std::string flat = std::regex_replace(readme, std::regex(R"(\s+)"), " ");
  ASSERT_TRUE(std::regex_search(flat, m, std::regex(R"(recording's model is ([0-9,]+) bytes)")));
  const std::string quoted = std::regex_replace(m[1].str(), std::regex(","), "");
  const std::string dir = ScratchDir("quoted_model_size");
  const auto run = RunShell(std::string(GRASPFILL_CLI) +
                            " replay " GRASPFILL_SOURCE_DIR "/replay/default/recording.lcmlog -o " + dir +
                            "/cloud.ply --lcm-url 'file://" + dir + "/bus.lcmlog?mode=w' 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  io::LcmLogReader reader(dir + "/bus.lcmlog");
  io::LogEvent event;
  size_t bytes = 0;
  while (reader.Next(&event) == io::LogReadResult::kEvent) {
    if (event.channel == "GRASPFILL_OBJECT_CLOUD") bytes = event.data.size();
  }
  EXPECT_EQ(std::to_string(bytes), quoted);
}

}  // namespace
}  // namespace graspfill
