#include "ground/gcs_feed.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "services/autopilot/mavlink/encoder.hpp"

namespace airseg::ground {

namespace proto = groundlink::protocol;
namespace mav = airseg::mavlink;

namespace {
// The vehicle's event when its autopilot rebooted (services/groundlink/groundlink_commands.cpp).
constexpr std::string_view kAutopilotRebooted = "autopilot rebooted: ";

autopilot::GcsEndpointConfig endpoint_config(const GcsConfig& c) {
    autopilot::GcsEndpointConfig e;
    e.udp = c.udp_listen;
    e.tcp = c.tcp;
    e.udp_remote = c.udp_listen.empty() ? std::string{} : c.udp_to;
    return e;
}
}  // namespace

GcsFeed::GcsFeed(asio::any_io_executor strand, Hub& hub, const GcsConfig& config)
    : hub_(hub),
      config_(config),
      endpoint_(std::move(strand), endpoint_config(config),
                [this](StationId station, std::vector<StationFrame> frames) {
                    from_station(station, std::move(frames));
                }) {}

std::string GcsFeed::start() {
    if (auto error = endpoint_.start(); !error.empty()) {
        return error;
    }
    hub_.add_listener([this](const proto::Message& m) {
        if (const auto* frames = std::get_if<proto::MavlinkFrames>(&m)) {
            from_vehicle(frames->bytes);
        } else if (const auto* e = std::get_if<proto::Event>(&m);
                   e != nullptr && e->text.starts_with(kAutopilotRebooted)) {
            params_.autopilot_rebooted();
        }
    });
    hub_.add_link_listener([this](const groundlink::TransportEvent& e) { on_link(e); });
    hub_.add_stats_source([this](nlohmann::json& stats) { stats["ground_stations"] = this->stats(); });
    return {};
}

void GcsFeed::stop() {
    endpoint_.stop();
}

void GcsFeed::from_vehicle(std::span<const std::uint8_t> bytes) {
    const auto reboots = params_.stats().reboots;
    std::vector<VehicleFrame> frames;
    vehicle_parser_.push(bytes, [&](const mav::Frame& f) {
        auto encoded = f.checksum_verified ? mav::reencode(f) : std::vector<std::uint8_t>{};
        if (encoded.empty()) {
            return;
        }
        params_.from_vehicle(f, encoded);
        frames.push_back(VehicleFrame{frame_target(f), std::move(encoded)});
    });
    endpoint_.from_vehicle(frames);
    if (params_.stats().reboots != reboots) {
        log_.log("ground hub: autopilot rebooted", std::chrono::steady_clock::now(), spdlog::level::info,
                 "ground hub: the autopilot's time since boot went back (a reboot): its parameters are asked "
                 "over the radio until a full download refills the hub's copy");
    }
}

void GcsFeed::from_station(StationId station, std::vector<StationFrame> frames) {
    std::vector<std::uint8_t> to_vehicle;
    for (const auto& f : frames) {
        std::vector<std::uint8_t> answer;
        if (params_.answer(f.frame, answer)) {
            endpoint_.to_station(station, answer);
            continue;
        }
        to_vehicle.insert(to_vehicle.end(), f.bytes.begin(), f.bytes.end());
    }
    if (to_vehicle.empty()) {
        return;
    }
    if (hub_.send_to_vehicle(proto::MavlinkFrames{std::move(to_vehicle)}) !=
            groundlink::SendResult::Accepted &&
        refused_++ % 100 == 0) {
        spdlog::warn("ground hub: a ground station's MAVLink could not be queued for the vehicle");
    }
}

void GcsFeed::on_link(const groundlink::TransportEvent& e) {
    using Kind = groundlink::TransportEvent::Kind;
    const auto now = std::chrono::steady_clock::now();
    if (e.kind == Kind::LinkDown) {
        down_since_ = now;
    } else if (e.kind == Kind::LinkUp) {
        // Through a short outage the vehicle queues every parameter value, so the cache stays true; after a
        // long one its queue may have overflowed.
        if (down_since_ && now - *down_since_ > ParamCache::kOutageKept) {
            params_.reset();
        }
        down_since_.reset();
    } else if (e.kind == Kind::PeerRestarted) {
        params_.reset();  // a new session with the vehicle: what it queued for the old one is gone
    }
}

nlohmann::json GcsFeed::stats() const {
    const auto s = endpoint_.stats();
    const auto p = params_.stats();
    return {{"frames_in", s.io.frames_in},
            {"invalid_in", s.io.invalid_in},
            {"bytes_out", s.io.bytes_out},
            {"dropped_out", s.io.dropped_out},
            {"udp_peers", s.io.udp_peers},
            {"tcp_clients", s.io.tcp_clients},
            {"broadcast", s.routing.broadcast},
            {"routed", s.routing.routed},
            {"unrouted", s.routing.unrouted},
            {"to_airsegd", s.routing.to_airsegd},
            {"senders_refused", s.routing.senders_refused},
            {"params",
             {{"fresh", params_.fresh()},
              {"entries", p.entries},
              {"count", p.count},
              {"overflow", p.overflow},
              {"resets", p.resets},
              {"reboots", p.reboots},
              {"answered_lists", p.answered_lists},
              {"answered_reads", p.answered_reads},
              {"passed_on", p.passed_on}}},
            {"to_vehicle_refused", refused_}};
}

std::string GcsFeed::where() const {
    std::string out;
    if (!config_.udp_listen.empty()) {
        const auto host = config_.udp_listen.substr(0, config_.udp_listen.rfind(':'));
        out = fmt::format("udp {}:{}", host, endpoint_.udp_port());
        if (!config_.udp_to.empty()) {
            out += " (sending to " + config_.udp_to + ")";
        }
    }
    if (!config_.tcp.empty()) {
        const auto host = config_.tcp.substr(0, config_.tcp.rfind(':'));
        out += fmt::format("{}tcp {}:{}", out.empty() ? "" : ", ", host, endpoint_.tcp_port());
    }
    return out;
}

}  // namespace airseg::ground
