// SPDX-License-Identifier: BSD-3-Clause
// An argument no command option matches, with the nearest option of the
// command's usage text as a suggestion: the usage text is the one list of
// a command's options, so nothing else has to be kept in step with it.
#pragma once

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "number_parsing.hpp"

namespace graspfill::cli {

/// The edits (insert, delete, replace, swap of neighbours) from `a` to `b`.
inline size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

/// The word of `candidates` nearest to `word`, if it is near enough to be
/// a slip of the keyboard: one edit in a name (dashes aside) of up to 3
/// letters, two in a longer one; else empty.
inline std::string Nearest(const std::string& word, const std::vector<std::string>& candidates) {
  const size_t letters = word.size() - std::min(word.find_first_not_of('-'), word.size());
  std::string best;
  size_t best_distance = letters <= 3 ? 2 : 3;  // the first distance too far
  for (const std::string& c : candidates) {
    const size_t d = EditDistance(word, c);
    if (d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

/// Every "--name" in a usage text, once each, in order.
inline std::vector<std::string> OptionsIn(const std::string& usage) {
  std::vector<std::string> options;
  for (size_t at = usage.find("--"); at != std::string::npos; at = usage.find("--", at + 2)) {
    if (at > 0 && !std::isspace(static_cast<unsigned char>(usage[at - 1])) && usage[at - 1] != '[' &&
        usage[at - 1] != '(' && usage[at - 1] != '|') {
      continue;
    }
    size_t end = at + 2;
    while (end < usage.size() && (std::isalnum(static_cast<unsigned char>(usage[end])) || usage[end] == '-'))
      ++end;
    const std::string name = usage.substr(at, end - at);
    if (name.size() > 2 && std::find(options.begin(), options.end(), name) == options.end()) {
      options.push_back(name);
    }
  }
  return options;
}

/// "bad option '<arg>'", then " (did you mean --x?)" where an option of
/// `usage` is a slip away, for the command's usage error.
inline std::string BadOptionText(const std::string& arg, const std::string& usage) {
  std::string text = (arg.rfind('-', 0) == 0 ? "bad option '" : "bad argument '") + arg + "'";
  const std::string name = arg.substr(0, arg.find('='));
  if (name.rfind("--", 0) == 0) {
    const std::string near = Nearest(name, OptionsIn(usage));
    if (!near.empty()) text += " (did you mean " + near + "?)";
  }
  return text;
}

/// The usage error of an argument no option matches (BadOptionText).
inline UsageError BadOption(const std::string& arg, const std::string& usage) {
  return UsageError(BadOptionText(arg, usage));
}

}  // namespace graspfill::cli
