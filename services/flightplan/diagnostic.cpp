#include "services/flightplan/diagnostic.hpp"

namespace airseg::flightplan {

std::string Diagnostic::to_string() const {
    std::string out = file.empty() ? std::string("<plan>") : file;
    if (line > 0) {
        out += ':' + std::to_string(line) + ':' + std::to_string(col);
    }
    out += ": ";
    if (!path.empty()) {
        out += path + ": ";
    }
    out += message;
    return out;
}

std::string to_string(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    for (const auto& d : diagnostics) {
        out += d.to_string() + '\n';
    }
    return out;
}

}  // namespace airseg::flightplan
