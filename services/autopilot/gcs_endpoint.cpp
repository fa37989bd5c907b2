#include "services/autopilot/gcs_endpoint.hpp"

#include <spdlog/spdlog.h>

namespace airseg::autopilot {

namespace {

StationSockets::Handlers handlers(GcsEndpoint::ToVehicle to_vehicle) {
    return {[to_vehicle = std::move(to_vehicle)](StationId, std::vector<StationFrame> frames) {
                if (!to_vehicle) {
                    return;
                }
                std::vector<std::uint8_t> bytes;
                for (const auto& f : frames) {
                    bytes.insert(bytes.end(), f.bytes.begin(), f.bytes.end());
                }
                to_vehicle(std::move(bytes));
            },
            {}};
}

}  // namespace

GcsEndpoint::GcsEndpoint(asio::any_io_executor strand, GcsEndpointConfig config, ToVehicle to_vehicle)
    : sockets_(std::move(strand), std::move(config), "gcs endpoint", kMaxTcpBacklog,
               handlers(std::move(to_vehicle))) {}

GcsEndpoint::~GcsEndpoint() = default;

std::string GcsEndpoint::start() {
    if (auto error = sockets_.start(); !error.empty()) {
        return error;
    }
    spdlog::info("gcs endpoint: MAVLink for ground stations on{}{}",
                 udp_port() == 0 ? "" : " udp port " + std::to_string(udp_port()),
                 tcp_port() == 0 ? "" : " tcp port " + std::to_string(tcp_port()));
    return {};
}

void GcsEndpoint::stop() {
    sockets_.stop();
}

void GcsEndpoint::from_vehicle(std::span<const std::uint8_t> frames) {
    for (const auto station : sockets_.stations()) {
        sockets_.send(station, frames);
    }
}

std::uint16_t GcsEndpoint::udp_port() const {
    return sockets_.udp_port();
}
std::uint16_t GcsEndpoint::tcp_port() const {
    return sockets_.tcp_port();
}
GcsEndpointStats GcsEndpoint::stats() const {
    return sockets_.stats();
}

}  // namespace airseg::autopilot
