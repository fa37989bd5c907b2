#pragma once
// The live map of airseg-ground: a small local web server (HTTP/1.1 on Boost.Beast: kept-alive connections,
// pipelined requests answered in order) serving the map page, the
// plan and the vehicle's track as they change (server-sent events), exports as GeoJSON and KML, and, when
// allowed, the plan commands (load, pause, resume, skip) passed to the vehicle through the hub.
//
// Everything runs on the strand given; the hub feeds it from that strand.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "groundside/event_wording.hpp"
#include "services/common/asio.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::ground {

struct MapConfig {
    std::string listen = "127.0.0.1:8080";  // HOST:PORT; port 0 = any (tests)
    std::string leaflet_dir = "/usr/share/javascript/leaflet";
    std::string web_dir;   // the page's own files; default: installed share dir, or the source dir (tests)
    std::string tile_url;  // empty: offline grid
    bool control = false;  // buttons command the vehicle; otherwise they are shown disabled
    std::vector<std::string> host_names;  // names the map answers to besides addresses and localhost
    // A request must arrive within request_deadline of the connection or of the previous answer (else 408, or
    // for a kept-alive connection with nothing more to ask, a close without a word); a client must take an
    // answer within answer_deadline (else its connection is closed). Shorter only in tests.
    std::chrono::milliseconds request_deadline{15'000};
    std::chrono::milliseconds answer_deadline{30'000};
};

/// The page's files: `configured` when given, else the installed ones, else the source tree's.
std::string map_web_dir(const std::string& configured);

class MapServer {
  public:
    /// Sends one vehicle command ({"cmd":"plan.pause"} ...) and calls done once with the vehicle's answer
    /// ({"ok":true,"result":...} or {"ok":false,"error":...}); runs on the same strand.
    using CommandSink = std::function<void(nlohmann::json request, std::function<void(nlohmann::json)> done)>;

    /// Points of the track kept (the oldest go first).
    static constexpr std::size_t kTrackPoints = 10000;
    /// Connections for requests (pages, files, exports, commands), kept alive between requests. When all are
    /// taken, the one that has waited longest for its next request is closed for a newcomer (idle or slow
    /// clients cannot lock out the page); only when every one is being answered is a newcomer answered 503.
    static constexpr std::size_t kMaxConnections = 64;
    /// Event streams (/events, one per open map tab), apart from the requests above: the 33rd is answered
    /// 503, and however many there are, pages and exports are still served.
    static constexpr std::size_t kMaxStreams = 32;

    struct Counts {
        std::uint64_t accepted = 0;         // connections accepted since start
        std::uint64_t evicted_idle = 0;     // closed before their request for a newcomer
        std::uint64_t refused_busy = 0;     // answered 503: every request slot was being answered
        std::uint64_t refused_streams = 0;  // /events answered 503: kMaxStreams open
        std::uint64_t accept_errors = 0;    // accepting failed (out of descriptors): retried shortly
        std::uint64_t request_timeouts = 0;  // no whole request within request_deadline: 408, or closed
        std::uint64_t answers_cut_off = 0;   // a client took no answer within answer_deadline: closed
        std::size_t streams = 0;            // event streams open now
    };

    MapServer(asio::any_io_executor strand, MapConfig config, CommandSink sink);
    ~MapServer();
    MapServer(const MapServer&) = delete;
    MapServer& operator=(const MapServer&) = delete;

    /// Binds; returns an error for people ("cannot listen on ...: ...") or empty.
    std::string start();
    void stop();
    /// The bound port.
    std::uint16_t port() const;
    /// Browser connections accepted since start (read on the server's strand).
    std::uint64_t connections_accepted() const;
    /// What the bounds did (read on the server's strand).
    Counts counts() const;

    // Fed by the hub, on the strand:
    /// The answer of plan.geometry, with what plan.show adds when known: "waypoints" (the expanded plan's
    /// count, null when endless) and "top" (the top-level elements: path, kind, name, waypoints).
    void set_plan(const nlohmann::json& geometry);
    void add_position(const groundlink::protocol::Telemetry& t, std::chrono::system_clock::time_point at);
    /// {"link":"up","rtt_ms":..,"loss":..,...}. While it is not up, the map adds "down_since" (when it went
    /// down, or when the map first heard of it) and "last" (the figures of the last time it was up).
    void set_link(const nlohmann::json& link);
    /// A vehicle event, worded in plan terms and de-duplicated (groundside/event_wording.hpp): the page
    /// lists the lines that are no debug line, and all of them in its debug view.
    void add_event(const groundlink::protocol::Event& e);
    /// A note of the map's own (info, never a debug line).
    void add_event(const std::string& text);

    struct Impl;

  private:
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::ground
