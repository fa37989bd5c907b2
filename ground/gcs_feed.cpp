#include "ground/gcs_feed.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace airseg::ground {

namespace proto = groundlink::protocol;

namespace {
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
      endpoint_(std::move(strand), endpoint_config(config), [this](std::vector<std::uint8_t> frames) {
          if (hub_.send_to_vehicle(proto::MavlinkFrames{std::move(frames)}) !=
                  groundlink::SendResult::Accepted &&
              refused_++ % 100 == 0) {
              spdlog::warn("ground hub: a ground station's MAVLink could not be queued for the vehicle");
          }
      }) {}

std::string GcsFeed::start() {
    if (auto error = endpoint_.start(); !error.empty()) {
        return error;
    }
    hub_.add_listener([this](const proto::Message& m) {
        if (const auto* frames = std::get_if<proto::MavlinkFrames>(&m)) {
            endpoint_.from_vehicle(frames->bytes);
        }
    });
    return {};
}

void GcsFeed::stop() {
    endpoint_.stop();
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
