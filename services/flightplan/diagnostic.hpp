#pragma once
// One problem found in a plan, located as precisely as the source allows:
// "plans/survey.yaml:12:9: plan.elements[3].scan.spacing: must be > 0".
#include <cstddef>
#include <string>
#include <vector>

namespace airseg::flightplan {

struct Diagnostic {
    std::string file;
    int line = 0;  // 1-based, 0 when unknown
    int col = 0;   // 1-based, 0 when unknown
    std::string path;
    std::string message;
    std::string to_string() const;
};

/// The first kMaxListedDiagnostics, one per line, then "... and N more errors".
inline constexpr std::size_t kMaxListedDiagnostics = 50;
std::string to_string(const std::vector<Diagnostic>& diagnostics);

}  // namespace airseg::flightplan
