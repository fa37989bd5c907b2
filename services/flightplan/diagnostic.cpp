#include "services/flightplan/diagnostic.hpp"

#include <algorithm>

#include "base/utf8.hpp"

namespace airseg::flightplan {

std::string Diagnostic::to_string() const {
    std::string out = file.empty() ? std::string("<plan>") : file;
    if (line > 0) {
        out += ':' + std::to_string(line) + ':' + std::to_string(col);
    }
    out += ": ";
    // A path holds the plan's own keys, a message may quote its names: cut, so that a megabyte-long key is
    // not echoed whole.
    if (!path.empty()) {
        out += excerpt(path, 200) + ": ";
    }
    out += excerpt(message, 400);
    return out;
}

std::string to_string(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    const std::size_t listed = std::min(diagnostics.size(), kMaxListedDiagnostics);
    for (std::size_t i = 0; i < listed; ++i) {
        out += diagnostics[i].to_string() + '\n';
    }
    if (diagnostics.size() > listed) {
        out += "... and " + std::to_string(diagnostics.size() - listed) + " more errors\n";
    }
    return out;
}

}  // namespace airseg::flightplan
