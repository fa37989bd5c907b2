#pragma once
// Which requests the map serves and which may command the vehicle. Any web page the operator's browser opens
// can send requests to the map: a page on another origin can POST to /api/command without reading the answer
// (a "no-cors" fetch), and a page on a name the attacker controls can rebind that name to 127.0.0.1 (DNS
// rebinding) and read the map as its own. So every request must name this server in its Host, and a command
// must come from this server's own page: an Origin, when sent, that is this server, and the page's token in
// X-Airseg-Token (a header no cross-origin page can send without a CORS preflight, which the map refuses).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ground/map/http.hpp"

namespace airseg::ground {

inline constexpr std::string_view kTokenHeader = "x-airseg-token";

struct RequestGuard {
    std::vector<std::string> names;  // host names the map answers to besides IP addresses and localhost
    std::string token;               // the page's token: only the map's own page is given it

    /// Why the request's Host does not name this server (nullopt: it does). IP literals and localhost always
    /// do, on any port (an SSH tunnel moves it); another name only when configured (--map-host).
    std::optional<std::string> host_refusal(const http::Request& req) const;
    /// Why the request may not command the vehicle (nullopt: it may).
    std::optional<std::string> command_refusal(const http::Request& req) const;
};

/// 32 hexadecimal digits from the system's random source.
std::string random_token();

}  // namespace airseg::ground
