# SPDX-License-Identifier: BSD-3-Clause
# cmake -DFROM=<file> -DTO=<file> -P AppendFile.cmake: adds FROM's text at
# the end of TO (a build step; no shell redirection needed).
file(READ "${FROM}" text)
file(APPEND "${TO}" "${text}")
