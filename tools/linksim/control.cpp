#include "tools/linksim/control.hpp"

#include <functional>
#include <sstream>
#include <vector>

#include "cli/values.hpp"

namespace airseg::linksim {

namespace {

std::vector<std::string> words(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::vector<std::string> out;
    for (std::string w; in >> w;) {
        out.push_back(w);
    }
    return out;
}

// Directions named by an optional third word: ab, ba or both (default).
std::vector<Side> directions(const std::vector<std::string>& w) {
    if (w.size() < 3 || w[2] == "both") {
        return {Side::A, Side::B};
    }
    if (w[2] == "ab") {
        return {Side::A};
    }
    if (w[2] == "ba") {
        return {Side::B};
    }
    throw cli::UsageError(w[0] + ": direction must be ab, ba or both, got '" + w[2] + "'");
}

}  // namespace

std::string apply_control(RadioModel& model, std::string_view command, TimePoint now) {
    const auto w = words(command);
    if (w.empty()) {
        return "error: empty command";
    }
    try {
        const std::string& verb = w[0];
        if ((verb == "down" || verb == "up") && w.size() == 2 && (w[1] == "a" || w[1] == "b")) {
            model.set_radio_down(w[1] == "a" ? Side::A : Side::B, verb == "down", now);
            return "ok radio " + w[1] + (verb == "down" ? " down" : " up");
        }
        if (verb == "down" || verb == "up") {
            return "error: " + verb + " needs a or b";
        }
        using Apply = std::function<void(Side, std::string_view)>;
        Apply apply;
        if (verb == "outage") {
            apply = [&](Side s, std::string_view v) {
                model.add_outage(s, now, cli::parse_seconds(verb, v));
            };
        } else if (verb == "loss") {
            apply = [&](Side s, std::string_view v) {
                model.impairment(s).byte_loss = cli::parse_probability(verb, v);
            };
        } else if (verb == "ber") {
            apply = [&](Side s, std::string_view v) {
                model.impairment(s).bit_error_rate = cli::parse_probability(verb, v);
            };
        } else if (verb == "corrupt") {
            apply = [&](Side s, std::string_view v) {
                model.impairment(s).byte_corruption = cli::parse_probability(verb, v);
            };
        } else if (verb == "frame-loss") {
            apply = [&](Side s, std::string_view v) {
                model.impairment(s).frame_loss = cli::parse_probability(verb, v);
            };
        } else if (verb == "latency") {
            apply = [&](Side s, std::string_view v) {
                model.impairment(s).latency = cli::parse_milliseconds(verb, v);
            };
        } else {
            return "error: unknown command '" + verb + "' (try help)";
        }
        if (w.size() < 2 || w.size() > 3) {
            return "error: usage: " + verb + " VALUE [ab|ba|both]";
        }
        const auto dirs = directions(w);
        // Each setter parses before it assigns, and the value is the same for every direction: a bad value
        // throws on the first one and changes nothing.
        for (Side s : dirs) {
            apply(s, w[1]);
        }
        return "ok " + std::string(command);
    } catch (const cli::UsageError& e) {
        return std::string("error: ") + e.what();
    }
}

}  // namespace airseg::linksim
