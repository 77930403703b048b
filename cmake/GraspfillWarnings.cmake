# SPDX-License-Identifier: BSD-3-Clause
# graspfill_target(<target>): C++17, warnings on, public headers from include/.
function(graspfill_warnings target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-deprecated-declarations)
endfunction()
