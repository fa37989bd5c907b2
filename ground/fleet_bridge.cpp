#include "ground/fleet_bridge.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "ground/fleet_command.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::ground {

namespace proto = groundlink::protocol;
using Json = nlohmann::json;

namespace {

constexpr int kQos0 = 0;
constexpr int kQos1 = 1;

double unix_now() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

groundside::MqttOptions session_options(const FleetConfig& config) {
    auto options = config.mqtt;
    // A persistent session: the broker keeps the cmd subscription and queues QoS 1 commands while the hub is
    // away, and hands them over when it is back.
    options.client_id = "airseg-ground-" + config.vehicle;
    options.clean_session = false;
    return options;
}

Json bad_request(const std::string& why) {
    return {{"ok", false}, {"status", "bad_request"}, {"error", why}};
}

}  // namespace

FleetBridge::FleetBridge(asio::any_io_executor strand, Hub& hub, FleetConfig config)
    : hub_(hub),
      config_(std::move(config)),
      session_(strand, session_options(config_),
               {.on_connection = [this](bool up, const std::string& why, bool) { on_connection(up, why); },
                .on_message =
                    [this](const std::string& topic, const std::string& payload) {
                        if (topic == this->topic("cmd")) {
                            on_command(payload);
                        }
                    }}),
      timer_(strand) {}

std::string FleetBridge::topic(std::string_view leaf) const {
    return "airseg/" + config_.vehicle + "/" + std::string(leaf);
}

std::string FleetBridge::start() {
    session_.set_will(topic("status"), Json{{"online", false}, {"vehicle", config_.vehicle}}.dump(), kQos1,
                      true);
    session_.subscribe(topic("cmd"), kQos1);
    if (auto error = session_.start(); !error.empty()) {
        return error;
    }
    hub_.add_listener([this](const proto::Message& m) { on_vehicle(m); });
    tick();
    return {};
}

void FleetBridge::stop() {
    if (stopped_) {
        return;
    }
    // A clean disconnect does not fire the will: say it ourselves.
    publish("status", {{"online", false}, {"vehicle", config_.vehicle}}, kQos1, true);
    stopped_ = true;
    timer_.cancel();
    session_.stop();
}

void FleetBridge::publish(std::string_view leaf, const Json& payload, int qos, bool retain) {
    if (!stopped_) {
        // The vehicle's texts (an autopilot's STATUSTEXT) may be any bytes: relayed, never thrown on.
        session_.publish(topic(leaf), payload.dump(-1, ' ', false, Json::error_handler_t::replace), qos,
                         retain);
    }
}

void FleetBridge::publish_status() {
    publish("status",
            {{"online", true}, {"link", link_}, {"vehicle", config_.vehicle}, {"hub", config_.hub_version}},
            kQos1, true);
}

void FleetBridge::publish_plan() {
    auto plan = *plan_;
    plan["at"] = unix_now();
    publish("plan", plan, kQos1, true);
}

void FleetBridge::on_connection(bool up, const std::string& why) {
    const auto broker = config_.mqtt.host + ":" + std::to_string(config_.mqtt.port);
    if (up) {
        spdlog::info("fleet: connected to the MQTT broker {} as airseg-ground-{}", broker, config_.vehicle);
        connected_ = true;
        last_why_.clear();
        publish_status();
        if (plan_) {
            publish_plan();  // a broker without persistence forgot it
        }
        return;
    }
    // Refusals (the broker's, TLS's) and a broker that is not there repeat on every retry; one line per
    // change of reason is enough.
    if (connected_ || why != last_why_) {
        spdlog::warn("fleet: MQTT broker {}: {}{}", broker, why, connected_ ? "; reconnecting" : "");
    }
    connected_ = false;
    last_why_ = why;
}

bool FleetBridge::first_time(const std::string& key, const Json& id) {
    if (auto it = answers_.find(key); it != answers_.end()) {
        if (it->second) {
            answer(id, *it->second);
        }
        return false;
    }
    answers_.emplace(key, std::nullopt);
    answer_order_.push_back(key);
    while (answer_order_.size() > kRememberedIds) {
        answers_.erase(answer_order_.front());
        answer_order_.pop_front();
    }
    return true;
}

void FleetBridge::answer(const Json& id, const Json& answer) {
    publish("cmd/result", {{"id", id}, {"answer", answer}}, kQos1);
}

void FleetBridge::on_command(const std::string& payload) {
    const auto message = Json::parse(payload, nullptr, false);
    if (message.is_discarded() || !message.is_object()) {
        answer(nullptr, bad_request("not a JSON object"));
        return;
    }
    const auto id = message.value("id", Json());
    if (!id.is_string() && !id.is_number()) {
        answer(nullptr, bad_request("\"id\" must be a string or a number"));
        return;
    }
    const auto request = message.find("request");
    if (request == message.end() || !request->is_object()) {
        answer(id, bad_request("no \"request\" object"));
        return;
    }
    const auto key = id.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (!first_time(key, id)) {
        spdlog::debug("fleet: command {} delivered again; not run twice", key);
        return;
    }
    spdlog::info("fleet: command {} {}", key,
                 request->value("cmd", Json()).dump(-1, ' ', false, Json::error_handler_t::replace));
    hub_.command(with_request_id(*request, id), [this, key, id](Json reply) {
        if (stopped_) {
            return;
        }
        if (auto it = answers_.find(key); it != answers_.end()) {
            it->second = reply;
        }
        answer(id, reply);
    });
}

void FleetBridge::on_vehicle(const proto::Message& message) {
    if (const auto* t = std::get_if<proto::Telemetry>(&message)) {
        auto vehicle = groundside::telemetry_json(*t);
        publish("telemetry", {{"at", unix_now()}, {"vehicle", vehicle}}, kQos0);
        Json plan = vehicle.value(
            "plan",
            Json{{"state", "none"}, {"element", t->plan_element}, {"next_waypoint", t->next_waypoint}});
        if (plan_ != plan) {
            plan_ = std::move(plan);
            publish_plan();
        }
    } else if (const auto* e = std::get_if<proto::Event>(&message)) {
        publish("events",
                {{"at", unix_now()},
                 {"severity", groundside::event_severity_name(e->severity)},
                 {"text", e->text}},
                kQos1);
    } else if (const auto* s = std::get_if<proto::LinkStatsReport>(&message)) {
        vehicle_link_ = *s;
    }
}

void FleetBridge::tick() {
    if (stopped_) {
        return;
    }
    const auto ground = hub_.link_stats();
    Json vehicle;
    if (vehicle_link_) {
        vehicle = {{"rtt_ms", vehicle_link_->rtt_ms},
                   {"loss_permille", vehicle_link_->loss_permille},
                   {"goodput_bps", vehicle_link_->goodput_bps},
                   {"retransmissions", vehicle_link_->retransmissions},
                   {"mac_failures", vehicle_link_->mac_failures}};
    }
    publish("link", {{"at", unix_now()}, {"ground", ground}, {"vehicle", vehicle}}, kQos0);
    if (auto link = ground.value("link", "down"); link != link_) {
        link_ = link;
        publish_status();
    }
    timer_.expires_after(std::chrono::seconds(1));
    timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec) {
            tick();
        }
    });
}

}  // namespace airseg::ground
