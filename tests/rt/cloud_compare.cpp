// SPDX-License-Identifier: BSD-3-Clause
// Test tool: compares two object clouds, each the last object_cloud_t on a
// channel of an LCM log (what `graspfill replay` and `graspfill live`
// published, captured with LCM's file:// provider or lcm-logger: whole, or
// object_cloud_chunk_t slices joined) or a PLY
// (`replay -o`): same number of points, each within a tolerance.
// usage: cloud_compare A.{lcmlog,ply} B.{lcmlog,ply} CHANNEL TOLERANCE_MM [identical|within|differ]
//   identical: every coordinate bit-equal; within: every point within the
//   tolerance; differ: some point farther than the tolerance (or the counts differ).
// Prints "points=<a>/<b> max_mm=<d> identical=<0|1>"; exit 0 when the
// expectation holds, 1 when not, 2 on bad input.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"

namespace {

std::optional<graspfill::ObjectCloud> LastCloud(const std::string& path, const std::string& channel) {
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".ply") == 0)
    return graspfill::io::ReadCloudPly(path);
  graspfill::io::LcmLogReader reader(path);
  graspfill::io::LogEvent event;
  std::optional<graspfill::ObjectCloud> last;
  graspfill::io::CloudChunkAssembler assembler;
  using Result = graspfill::io::CloudChunkAssembler::Result;
  while (reader.Next(&event) == graspfill::io::LogReadResult::kEvent) {
    if (event.channel != channel) continue;
    graspfill::ObjectCloud cloud;
    std::string error;
    const Result r = assembler.Add(event.data.data(), event.data.size(), &error);
    if (r == Result::kPending || r == Result::kRepeat) continue;
    if (r != Result::kComplete || !graspfill::io::DecodeObjectCloud(
                                      assembler.cloud().data(), assembler.cloud().size(), &cloud, &error)) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), error.c_str());
      std::exit(2);
    }
    last = std::move(cloud);
  }
  return last;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr,
                 "usage: %s A.{lcmlog,ply} B.{lcmlog,ply} CHANNEL TOLERANCE_MM identical|within|differ\n",
                 argv[0]);
    return 2;
  }
  const std::string expect = argv[5];
  const double tolerance_m = std::atof(argv[4]) * 1e-3;
  std::optional<graspfill::ObjectCloud> a, b;
  try {
    a = LastCloud(argv[1], argv[3]);
    b = LastCloud(argv[2], argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  if (!a || !b || a->points_G.empty()) {
    std::fprintf(stderr, "no (or an empty) cloud on %s in %s\n", argv[3], !a ? argv[1] : argv[2]);
    return 2;
  }
  const size_t na = a->points_G.size(), nb = b->points_G.size();
  double max_m = na == nb ? 0.0 : INFINITY;
  bool identical = na == nb;
  for (size_t i = 0; na == nb && i < na; ++i) {
    max_m = std::fmax(max_m, (a->points_G[i] - b->points_G[i]).cast<double>().norm());
    identical =
        identical && std::memcmp(a->points_G[i].data(), b->points_G[i].data(), 3 * sizeof(float)) == 0;
  }
  std::printf("points=%zu/%zu max_mm=%.6f identical=%d\n", na, nb, max_m * 1e3, identical ? 1 : 0);
  if (expect == "identical") return identical ? 0 : 1;
  if (expect == "within") return max_m <= tolerance_m ? 0 : 1;
  if (expect == "differ") return max_m > tolerance_m ? 0 : 1;
  std::fprintf(stderr, "unknown expectation '%s'\n", expect.c_str());
  return 2;
}
