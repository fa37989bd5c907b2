#include "client/vehicle_commands.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <optional>

#include "client/json_text.hpp"
#include "services/common/text.hpp"

namespace airseg::client {

namespace {

BuiltCommand usage(std::string why) {
    BuiltCommand b;
    b.usage_error = std::move(why);
    return b;
}

std::optional<double> number(const std::string& text) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(v)) {
        return std::nullopt;
    }
    return v;
}

std::string rates_text(const nlohmann::json& r) {
    std::string out;
    const auto field = [&r](const char* name) {
        const auto it = r.find(name);
        return it != r.end() && it->is_object() ? *it : nlohmann::json::object();
    };
    const nlohmann::json requested = field("requested_hz");
    const nlohmann::json effective = field("effective_hz");
    for (const auto& [kind, hz] : requested.items()) {
        out += fmt::format("{:<12} requested {:>6} Hz   effective {:>6} Hz\n", kind, dump_text(hz),
                           dump_text(effective.value(kind, nlohmann::json())));
    }
    out += fmt::format("link budget {} B/s, weak-link factor {}{}\n", r.value("budget_bytes_per_s", 0.0),
                       r.value("factor", 1.0), r.value("weak_link", false) ? " (link weak)" : "");
    return out;
}

BuiltCommand state_command(const std::vector<std::string>& a) {
    if (a.size() != 2) {
        return usage("state needs one STATE: PARKING, DIRECTED, MANUAL_NAVIGATION or WAYPOINT_NAVIGATION");
    }
    BuiltCommand b;
    b.request = {{"cmd", "state"}, {"state", to_upper(a[1])}};
    b.render = [](const nlohmann::json& r) {
        const auto armed = r.find("armed");
        const std::string arming =
            armed != r.end() && armed->is_boolean() ? (armed->get<bool>() ? " (armed)" : " (disarmed)") : "";
        return "vehicle acknowledged: state " + r.value("state", std::string("?")) + arming + "\n";
    };
    return b;
}

BuiltCommand param_command(const std::vector<std::string>& a) {
    const std::string sub = a.size() >= 2 ? a[1] : "";
    BuiltCommand b;
    if (sub == "get" && a.size() == 3) {
        b.request = {{"cmd", "param.get"}, {"name", to_upper(a[2])}};
        b.render = [](const nlohmann::json& r) {
            return fmt::format("{} = {}\n", r.value("name", "?"),
                               dump_text(r.value("value", nlohmann::json())));
        };
    } else if (sub == "set" && a.size() == 4) {
        const auto v = number(a[3]);
        if (!v) {
            return usage("param set: '" + a[3] + "' is not a number");
        }
        b.request = {{"cmd", "param.set"}, {"name", to_upper(a[2])}, {"value", *v}};
        b.render = [](const nlohmann::json& r) {
            return fmt::format("vehicle acknowledged: {} = {}\n", r.value("name", "?"),
                               dump_text(r.value("value", nlohmann::json())));
        };
    } else if (sub == "list" && a.size() == 2) {
        b.request = {{"cmd", "param.list"}};
        b.render = [](const nlohmann::json& r) {
            std::string out;
            const auto it = r.find("params");
            const nlohmann::json params = it != r.end() && it->is_object() ? *it : nlohmann::json::object();
            for (const auto& [name, value] : params.items()) {
                out += fmt::format("{:<16} {}\n", name, dump_text(value));
            }
            return out + fmt::format("{} parameters\n", r.value("count", 0));
        };
    } else {
        return usage("param needs: get NAME | set NAME VALUE | list");
    }
    return b;
}

BuiltCommand rates_command(const std::vector<std::string>& a) {
    BuiltCommand b;
    b.render = rates_text;
    if (a.size() == 1) {
        b.request = {{"cmd", "rates"}};
        return b;
    }
    nlohmann::json rates = nlohmann::json::object();
    for (std::size_t i = 1; i < a.size(); ++i) {
        const auto eq = a[i].find('=');
        const auto hz = eq == std::string::npos ? std::nullopt : number(a[i].substr(eq + 1));
        if (!hz || eq == 0) {
            return usage("rates takes KIND=HZ arguments, e.g. vehicle=5 link_stats=1");
        }
        rates[a[i].substr(0, eq)] = *hz;
    }
    b.request = {{"cmd", "rates.set"}, {"rates", rates}};
    return b;
}

}  // namespace

bool is_vehicle_command(const std::string& name) {
    return name == "state" || name == "param" || name == "rates";
}

BuiltCommand build_vehicle_command(const std::vector<std::string>& args) {
    if (args.empty()) {
        return usage("no command given");
    }
    if (args[0] == "state") {
        return state_command(args);
    }
    if (args[0] == "param") {
        return param_command(args);
    }
    if (args[0] == "rates") {
        return rates_command(args);
    }
    return usage("unknown command '" + args[0] + "'");
}

}  // namespace airseg::client
