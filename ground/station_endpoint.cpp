#include "ground/station_endpoint.hpp"

#include <map>

namespace airseg::ground {

StationEndpoint::StationEndpoint(asio::any_io_executor strand, autopilot::GcsEndpointConfig config,
                                 FromStation from_station)
    : from_station_(std::move(from_station)),
      sockets_(std::move(strand), std::move(config), "ground stations", kMaxTcpBacklog,
               {[this](StationId station, std::vector<StationFrame> frames) {
                    for (const auto& f : frames) {
                        router_.heard(station, f.frame.sysid, f.frame.compid);
                    }
                    if (from_station_) {
                        from_station_(station, std::move(frames));
                    }
                },
                [this](StationId station) { router_.forget(station); }}) {}

// The sockets call nothing once stopped, so the handlers' `this` never outlives the endpoint.
StationEndpoint::~StationEndpoint() {
    sockets_.stop();
}

std::string StationEndpoint::start() {
    return sockets_.start();
}

void StationEndpoint::stop() {
    sockets_.stop();
}

void StationEndpoint::from_vehicle(const std::vector<VehicleFrame>& frames) {
    if (frames.empty()) {
        return;
    }
    const auto stations = sockets_.stations();
    std::map<StationId, std::vector<std::uint8_t>> out;
    for (const auto& f : frames) {
        for (const auto station : router_.destinations(f.target, stations)) {
            auto& bytes = out[station];
            bytes.insert(bytes.end(), f.bytes.begin(), f.bytes.end());
        }
    }
    for (const auto& [station, bytes] : out) {
        sockets_.send(station, bytes);
    }
}

void StationEndpoint::to_station(StationId station, std::span<const std::uint8_t> frames) {
    sockets_.send(station, frames);
}

std::uint16_t StationEndpoint::udp_port() const {
    return sockets_.udp_port();
}
std::uint16_t StationEndpoint::tcp_port() const {
    return sockets_.tcp_port();
}
StationEndpointStats StationEndpoint::stats() const {
    return StationEndpointStats{sockets_.stats(), router_.stats()};
}

}  // namespace airseg::ground
