#pragma once
// "did you mean ...?" for a mistyped name: the configuration's keys, the programs' options, a plan's
// fields. Header-only so that every program and library can use it without a link dependency.
#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace airseg {

/// Levenshtein distance: insertions, deletions and substitutions of one character each count 1.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) {
        prev[j] = j;
    }
    for (std::size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

/// The candidate closest to `word`, when it is a near miss (at most two edits, and fewer than the word's
/// own length, so that short words do not match everything); empty otherwise.
template <typename Range>
std::string nearest_word(std::string_view word, const Range& candidates) {
    std::string best;
    std::size_t best_distance = std::min<std::size_t>(3, word.size());
    for (const auto& candidate : candidates) {
        const auto d = edit_distance(word, candidate);
        if (d < best_distance) {
            best_distance = d;
            best = std::string(candidate);
        }
    }
    return best;
}

/// " (did you mean 'X'?)" for a near miss, or nothing.
template <typename Range>
std::string did_you_mean(std::string_view word, const Range& candidates) {
    const auto best = nearest_word(word, candidates);
    return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

}  // namespace airseg
