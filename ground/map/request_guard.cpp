#include "ground/map/request_guard.hpp"

#include <algorithm>
#include <cctype>
#include <random>

#include <fmt/format.h>
#include <boost/asio/ip/address.hpp>

namespace airseg::ground {

namespace {

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return out;
}

struct HostPort {
    std::string host;  // without the brackets of an IPv6 literal
    bool ok = false;
};

HostPort split_host(std::string_view value) {
    HostPort out;
    std::string_view host = value;
    std::string_view port;
    if (value.starts_with('[')) {
        const auto close = value.find(']');
        if (close == std::string_view::npos) {
            return out;
        }
        host = value.substr(1, close - 1);
        const auto rest = value.substr(close + 1);
        if (!rest.empty()) {
            if (!rest.starts_with(':')) {
                return out;
            }
            port = rest.substr(1);
        }
    } else if (const auto colon = value.rfind(':'); colon != std::string_view::npos) {
        host = value.substr(0, colon);
        port = value.substr(colon + 1);
    }
    if (host.empty()) {
        return out;
    }
    if (!port.empty() || value.ends_with(':')) {
        if (port.empty() || port.size() > 5 ||
            !std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; })) {
            return out;
        }
    }
    out.host = lower(host);
    out.ok = true;
    return out;
}

bool is_ip_literal(const std::string& host) {
    boost::system::error_code ec;
    boost::asio::ip::make_address(host, ec);
    return !ec;
}

}  // namespace

std::optional<std::string> RequestGuard::host_refusal(const http::Request& req) const {
    const auto value = req.header("host");
    if (!value) {
        return std::string("no Host header");
    }
    const auto at = split_host(*value);
    const auto shown = std::string(value->substr(0, 100));
    if (!at.ok) {
        return "a Host that is no HOST:PORT ('" + shown + "')";
    }
    if (is_ip_literal(at.host) || at.host == "localhost" ||
        std::find(names.begin(), names.end(), at.host) != names.end()) {
        return std::nullopt;
    }
    return "Host '" + shown +
           "' is not a name of this map (an address, localhost, or one given with --map-host)";
}

std::optional<std::string> RequestGuard::command_refusal(const http::Request& req) const {
    if (const auto origin = req.header("origin")) {
        const auto host = req.header("host").value_or("");
        if (lower(*origin) != "http://" + lower(host)) {
            return "a page from " + std::string(origin->substr(0, 100)) + " may not command the vehicle";
        }
    }
    const auto given = req.header(kTokenHeader);
    if (!given || token.empty() || *given != token) {
        return std::string("not from this map's page (no or a wrong X-Airseg-Token; reload the page)");
    }
    return std::nullopt;
}

std::string random_token() {
    std::random_device source;
    std::string out;
    for (int i = 0; i < 4; ++i) {
        out += fmt::format("{:08x}", source());
    }
    return out;
}

}  // namespace airseg::ground
