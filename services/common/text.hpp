#pragma once
// Small text helpers shared by the daemon, the client and the tools.
#include <algorithm>
#include <cctype>
#include <string>

namespace airseg {

/// ASCII upper case (mode, state and parameter names are ASCII).
inline std::string to_upper(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return s;
}

/// ASCII lower case.
inline std::string to_lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

}  // namespace airseg
