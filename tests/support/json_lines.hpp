#pragma once
// The JSON objects of a program's line-per-record output (airsegctl --json watch, log); lines that are not
// JSON (a program's plain messages) are skipped.
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace airseg::test {

inline std::vector<nlohmann::json> json_lines(const std::string& text) {
    std::vector<nlohmann::json> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        auto j = nlohmann::json::parse(line, nullptr, false);
        if (!j.is_discarded()) {
            out.push_back(std::move(j));
        }
    }
    return out;
}

}  // namespace airseg::test
