#include "services/autopilot/gcs_endpoint_config.hpp"

#include "services/common/asio.hpp"

namespace airseg::autopilot {

std::optional<HostPort> parse_host_port(const std::string& text) {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == text.size() || colon + 6 < text.size()) {
        return std::nullopt;
    }
    unsigned long port = 0;
    for (char ch : text.substr(colon + 1)) {
        if (ch < '0' || ch > '9') {
            return std::nullopt;
        }
        port = port * 10 + static_cast<unsigned long>(ch - '0');
    }
    boost::system::error_code ec;
    asio::ip::make_address(text.substr(0, colon), ec);
    if (ec || port > 65535) {
        return std::nullopt;
    }
    return HostPort{text.substr(0, colon), static_cast<std::uint16_t>(port)};
}

std::vector<std::string> GcsEndpointConfig::validate() const {
    std::vector<std::string> problems;
    if (!udp.empty() && !parse_host_port(udp)) {
        problems.push_back("udp: \"" + udp + "\" is not ADDRESS:PORT (an IP address and a port 0..65535)");
    }
    if (!tcp.empty() && !parse_host_port(tcp)) {
        problems.push_back("tcp: \"" + tcp + "\" is not ADDRESS:PORT (an IP address and a port 0..65535)");
    }
    if (!udp_remote.empty()) {
        const auto r = parse_host_port(udp_remote);
        if (!r || r->port == 0) {
            problems.push_back("udp_remote: \"" + udp_remote + "\" is not ADDRESS:PORT with a port 1..65535");
        }
        if (udp.empty()) {
            problems.push_back("udp_remote: needs udp");
        }
    }
    return problems;
}

}  // namespace airseg::autopilot
