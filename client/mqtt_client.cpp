#include "client/mqtt_client.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <random>

#include "client/json_text.hpp"
#include "groundside/mqtt_options.hpp"
#include "groundside/watch_view.hpp"
#include "services/autopilot/ardupilot/rover_modes.hpp"

namespace airseg::client {

namespace proto = groundlink::protocol;
using Json = nlohmann::json;

namespace {

template <typename Name>
std::optional<std::uint8_t> code_named(const std::string& wanted, int last, Name name) {
    for (int code = 0; code <= last; ++code) {
        const char* n = name(static_cast<std::uint8_t>(code));
        if (n != nullptr && wanted == n) {
            return static_cast<std::uint8_t>(code);
        }
    }
    return std::nullopt;
}

proto::Event::Severity severity_named(const std::string& name) {
    return name == "error"     ? proto::Event::Severity::Error
           : name == "warning" ? proto::Event::Severity::Warning
                               : proto::Event::Severity::Info;
}

}  // namespace

std::optional<proto::Telemetry> telemetry_from_json(const Json& v) {
    if (!v.is_object() || !v.contains("lat")) {
        return std::nullopt;
    }
    // A sample without a fix has no place: lat and lon null, position_valid false.
    const auto valid = v.find("position_valid");
    const bool placeless = valid != v.end() && *valid == false;
    if (!v["lat"].is_number() && !(placeless && v["lat"].is_null())) {
        return std::nullopt;
    }
    proto::Telemetry t;
    if (!placeless) {
        t.lat_deg = v.value("lat", 0.0);
        t.lon_deg = v["lon"].is_number() ? v["lon"].get<double>() : 0.0;
    }
    t.alt_m = v.value("alt_m", 0.0);
    t.ground_speed_mps = v.value("ground_speed_mps", 0.0);
    t.heading_deg = v.value("heading_deg", 0.0);
    t.roll_deg = v.value("roll_deg", 0);
    t.pitch_deg = v.value("pitch_deg", 0);
    t.battery_v = v.value("battery_v", 0.0);
    if (v.contains("battery_pct") && v["battery_pct"].is_number()) {
        t.battery_pct = v["battery_pct"].get<int>();
    }
    t.gps_fix = v.value("gps_fix", std::uint8_t{0});
    t.satellites = v.value("satellites", std::uint8_t{0});
    t.no_position = placeless;
    t.vehicle_state = code_named(v.value("state", ""), 15, proto::vehicle_state_name).value_or(0);
    t.mode =
        code_named(v.value("mode", ""), proto::kModeUnknown - 1, autopilot::ardupilot::rover_mode_known_name)
            .value_or(proto::kModeUnknown);
    if (const auto plan = v.find("plan"); plan != v.end() && plan->is_object()) {
        t.plan_state = code_named(plan->value("state", ""), 5, groundside::plan_state_name).value_or(0);
        t.plan_element = plan->value("element", std::uint16_t{0});
        t.next_waypoint = plan->value("next_waypoint", std::uint32_t{0});
    }
    return t;
}

MqttClient::MqttClient(groundside::MqttOptions options, std::string vehicle)
    : vehicle_(std::move(vehicle)), broker_(options.host, options.port) {
    std::random_device rd;
    options.client_id = fmt::format("airsegctl-{}-{:08x}", ::getpid(), rd());
    options.clean_session = true;
    session_ = std::make_unique<groundside::MqttSession>(
        io_.get_executor(), std::move(options),
        groundside::MqttSession::Handlers{
            [this](bool up, const std::string& why, bool definitive) {
                connected_ = up;
                if (!up && !why.empty()) {
                    refused_ = why;
                    definitive_ = definitive;
                }
            },
            [this](const std::string& topic, const std::string& payload) { on_message(topic, payload); }});
}

MqttClient::~MqttClient() {
    session_->stop();
}

std::string MqttClient::open(std::chrono::milliseconds timeout) {
    for (const auto* kind : {"cmd/result", "telemetry", "events", "link", "status"}) {
        session_->subscribe(groundside::vehicle_topic(vehicle_, kind), 1);
    }
    if (auto error = session_->start(); !error.empty()) {
        return error;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!connected_ && std::chrono::steady_clock::now() < deadline) {
        io_.run_for(std::chrono::milliseconds(20));
        io_.restart();
        // A refusal or a TLS failure would only repeat: said at once. A broker not there yet may come.
        if (definitive_) {
            return fmt::format("MQTT broker {}:{}: {}", broker_.first, broker_.second, refused_);
        }
    }
    if (!connected_) {
        return fmt::format("no connection to the MQTT broker within {} ms{}", timeout.count(),
                           refused_.empty() ? "" : " (" + refused_ + ")");
    }
    return {};
}

void MqttClient::on_message(const std::string& topic, const std::string& payload) {
    const auto prefix = groundside::vehicle_topic(vehicle_, "");
    if (topic.rfind(prefix, 0) != 0) {
        return;
    }
    const auto kind = topic.substr(prefix.size());
    auto j = Json::parse(payload, nullptr, false);
    if (!j.is_object()) {
        return;
    }
    if (kind == "cmd/result") {
        const auto id = j.value("id", Json());
        if (!awaiting_.empty() && id.is_string() && id.get<std::string>() == awaiting_) {
            answer_ = j.value("answer", Json::object());
        }
        return;
    }
    if (kind == "status") {
        if (!j.value("online", false)) {
            link_["link"] = "down";
        }
        return;
    }
    if (kind == "link") {
        if (j["ground"].is_object()) {
            link_ = j["ground"];
        }
        if (const auto& v = j["vehicle"]; v.is_object() && on_message_) {
            on_message_(proto::LinkStatsReport{
                v.value("rtt_ms", std::uint16_t{0}), v.value("loss_permille", std::uint16_t{0}),
                v.value("goodput_bps", std::uint32_t{0}), v.value("retransmissions", std::uint32_t{0}),
                v.value("mac_failures", std::uint32_t{0})});
        }
        return;
    }
    if (!on_message_) {
        return;
    }
    if (kind == "telemetry") {
        if (auto t = telemetry_from_json(j["vehicle"])) {
            on_message_(*t);
        }
    } else if (kind == "events") {
        on_message_(proto::Event{severity_named(j.value("severity", "info")), j.value("text", "")});
    }
}

LocalAnswer MqttClient::request(const Json& request, std::chrono::milliseconds timeout,
                                const MessageHandler& on_message) {
    on_message_ = on_message;  // the pushes while it waits, as run_for sees them
    LocalAnswer out = exchange(request, timeout);
    on_message_ = nullptr;
    return out;
}

LocalAnswer MqttClient::exchange(const Json& request, std::chrono::milliseconds timeout) {
    LocalAnswer out;
    std::random_device rd;
    awaiting_ = fmt::format("{:08x}{:08x}", rd(), rd());
    answer_.reset();
    const Json message{{"id", awaiting_}, {"request", request}};
    if (!session_->publish(groundside::vehicle_topic(vehicle_, "cmd"), dump_text(message), 1, false)) {
        out.error = "the command could not be queued for the MQTT broker";
        return out;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!answer_ && std::chrono::steady_clock::now() < deadline) {
        io_.run_for(std::chrono::milliseconds(20));
        io_.restart();
    }
    awaiting_.clear();
    if (!answer_) {
        out.error = fmt::format(
            "no answer from vehicle {} within {} ms (through the MQTT broker; is its hub connected, and may "
            "this "
            "user publish commands?)",
            vehicle_, timeout.count());
        return out;
    }
    out.answer = std::move(answer_);
    return out;
}

void MqttClient::run_for(std::chrono::milliseconds duration,
                         const std::function<void(const proto::Message&)>& on_message) {
    on_message_ = on_message;
    io_.run_for(duration);
    io_.restart();
    on_message_ = nullptr;
}

}  // namespace airseg::client
