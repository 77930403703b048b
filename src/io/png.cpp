// SPDX-License-Identifier: BSD-3-Clause
// PNG through Open3D's image I/O (libpng underneath), into a temporary file
// that replaces the target only once it is complete.
#include "graspfill/io/png.hpp"

#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "graspfill/io/atomic_file.hpp"

namespace graspfill::io {

void WritePng(const std::string& path, const RgbImage& image, IfExists if_exists) {
  const std::string what = "cannot write PNG";
  auto fail = [&](const std::string& why) { throw std::runtime_error(what + " '" + path + "': " + why); };
  if (image.width <= 0 || image.height <= 0) fail("the image is empty");
  if (image.rgb.size() != static_cast<size_t>(image.width) * image.height * 3) {
    fail("the pixel buffer is not width x height x 3 bytes");
  }
  open3d::geometry::Image o3d;
  o3d.Prepare(image.width, image.height, /*num_of_channels=*/3, /*bytes_per_channel=*/1);
  std::memcpy(o3d.data_.data(), image.rgb.data(), image.rgb.size());
  AtomicFile file(path, what, if_exists);
  // By the format's own writer: the temporary name has no .png extension
  // for WriteImage to go by. It says only true or false; errno tells why
  // where the system failed it (a full disk).
  errno = 0;
  if (!open3d::io::WriteImageToPNG(file.temp_path(), o3d)) {
    const int error = errno;
    fail(error != 0 ? std::string("the PNG encoder failed: ") + std::strerror(error)
                    : std::string("the PNG encoder failed"));
  }
  file.Commit();
}

}  // namespace graspfill::io
