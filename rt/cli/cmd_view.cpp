// SPDX-License-Identifier: BSD-3-Clause
// graspfill view CLOUD.ply [AFTER.ply] -o VIEW.png: a picture of object
// clouds in their provenance colours, with a legend (view/contact_sheet.hpp);
// given two clouds, before and after side by side at one scale. A PLY with
// faces (a collision mesh) is drawn as a surface.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.hpp"
#include "error_text.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/io/png.hpp"
#include "graspfill/view/contact_sheet.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kViewUsage =
    "usage: graspfill view CLOUD.ply [AFTER.ply] -o VIEW.png [--views N] [--force]\n"
    "  CLOUD.ply   an object cloud (graspfill's PLY: provenance colours; any other PLY: observed);\n"
    "              a PLY with faces (e.g. --mesh-out's) is drawn as a shaded surface\n"
    "  AFTER.ply   a second cloud, drawn beside the first at the same scale (before / after)\n"
    "  -o PATH     the picture (PNG): a column per cloud, a row per view, a legend\n"
    "  --views N   views about the gripper axis, 1..12 (default 3)\n"
    "  --force     overwrite the picture if it exists\n"
    "example: graspfill view scan.ply repaired.ply -o before_after.png\n";

struct ViewOptions {
  std::vector<std::string> clouds;
  std::string output_path;
  bool force{false};
  view::SheetConfig sheet;
};

// Throws UsageError (printed with the usage text, exit code 2).
void Parse(const Args& args, ViewOptions* o) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "-o" || a == "--output")
      o->output_path = value();
    else if (a == "--views")
      o->sheet.views = ParseInteger<int>("--views", value(), 1, 12);
    else if (a == "--force")
      o->force = true;
    else if (!a.empty() && a[0] != '-')
      o->clouds.push_back(a);
    else
      throw BadOption(a, kViewUsage);
  }
  if (o->clouds.empty()) throw UsageError("need a CLOUD.ply");
  if (o->clouds.size() > 2) throw UsageError("at most two clouds (before and after)");
  if (o->output_path.empty()) throw UsageError("need -o VIEW.png");
  if (std::filesystem::path(o->output_path).extension() != ".png") {
    throw UsageError("-o '" + o->output_path + "': the picture is a PNG, name it .png");
  }
}

}  // namespace

int RunView(const Args& args) {
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kViewUsage, stdout);
      return 0;
    }
  }
  ViewOptions o;
  try {
    Parse(args, &o);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill view: %s\n%s", e.what(), kViewUsage);
    return 2;
  }
  try {
    io::CheckOutputFile(o.output_path, o.force);  // before reading the clouds
    std::vector<ObjectCloud> clouds;
    std::vector<TriangleMesh> meshes(o.clouds.size());  // empty: a cloud
    for (size_t i = 0; i < o.clouds.size(); ++i) {
      clouds.push_back(io::ReadCloudFile(o.clouds[i]));  // a .pcd is refused here
      meshes[i].triangles = io::ReadPlyTriangles(o.clouds[i]);
      meshes[i].vertices = clouds[i].points_G;
    }
    std::vector<view::SheetCloud> sheet;
    for (size_t i = 0; i < clouds.size(); ++i) {
      std::string title = std::filesystem::path(o.clouds[i]).filename().string();
      if (clouds.size() == 2) title = (i == 0 ? "before: " : "after: ") + title;
      sheet.push_back({&clouds[i], title, meshes[i].empty() ? nullptr : &meshes[i]});
    }
    const RgbImage image = view::RenderSheet(sheet, o.sheet);
    io::WritePng(o.output_path, image, io::ReplaceIf(o.force));
    std::printf("wrote %s: %zu cloud(s) x %d view(s), %d x %d pixels\n", o.output_path.c_str(), clouds.size(),
                o.sheet.views, image.width, image.height);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill view: %s\n", ErrorText(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace graspfill::cli
