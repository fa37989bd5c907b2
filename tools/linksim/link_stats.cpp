#include "tools/linksim/link_stats.hpp"

#include <iomanip>
#include <sstream>

namespace airseg::linksim {

namespace {

nlohmann::json direction_json(const RadioModel& model, Side from, TimePoint now) {
    const DirectionStats& s = model.stats(from);
    return {{"bytes_in", s.bytes_in},
            {"bytes_refused", s.bytes_refused},
            {"bytes_out", s.bytes_out},
            {"overflow_dropped", s.overflow_dropped},
            {"rx_overflow_dropped", s.rx_overflow_dropped},
            {"bytes_lost", s.bytes_lost},
            {"bytes_corrupted", s.bytes_corrupted},
            {"packets_sent", s.packets_sent},
            {"packets_lost", s.packets_lost},
            {"outage_packets_lost", s.outage_packets_lost},
            {"down_dropped", s.down_dropped},
            {"air_time_s", std::chrono::duration<double>(s.air_time).count()},
            {"air_utilisation", model.air_utilisation(from, now)}};
}

nlohmann::json host_json(const RadioModel& model, const HostStats& h, Side side) {
    return {{"peer_connected", h.peer_connected},
            {"radio_down", model.radio_down(side)},
            {"backlog_dropped", h.backlog_dropped},
            {"not_written", h.not_written}};
}

}  // namespace

nlohmann::json stats_json(const RadioModel& model, const std::array<HostStats, 2>& hosts, TimePoint now) {
    return {{"elapsed_s", std::chrono::duration<double>(now - model.start()).count()},
            {"ab", direction_json(model, Side::A, now)},
            {"ba", direction_json(model, Side::B, now)},
            {"a", host_json(model, hosts[0], Side::A)},
            {"b", host_json(model, hosts[1], Side::B)}};
}

std::string stats_text(const RadioModel& model, const std::array<HostStats, 2>& hosts, TimePoint now) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(1)
       << "linksim: " << std::chrono::duration<double>(now - model.start()).count() << " s\n";
    for (Side from : {Side::A, Side::B}) {
        const DirectionStats& s = model.stats(from);
        os << "  " << to_string(from) << "->" << to_string(other(from)) << ": in " << s.bytes_in << " out "
           << s.bytes_out << " overflow " << s.overflow_dropped << " lost " << s.bytes_lost << " corrupted "
           << s.bytes_corrupted << " packets " << s.packets_sent << " (lost " << s.packets_lost << ", outage "
           << s.outage_packets_lost << ") refused " << s.bytes_refused << " down " << s.down_dropped
           << " air " << std::setprecision(1)
           << 100.0 * std::chrono::duration<double>(s.air_time).count() /
                  std::max(1e-9, std::chrono::duration<double>(now - model.start()).count())
           << " %\n";
    }
    os << "  air utilisation " << std::setprecision(1) << 100.0 * model.air_utilisation(Side::A, now) << " %";
    if (model.config().duplex == Duplex::Full) {
        os << " / " << 100.0 * model.air_utilisation(Side::B, now) << " %";
    }
    os << '\n';
    for (Side side : {Side::A, Side::B}) {
        const HostStats& h = hosts[index(side)];
        os << "  host " << to_string(side) << ": " << (h.peer_connected ? "connected" : "no peer")
           << (model.radio_down(side) ? ", radio down" : "") << ", backlog dropped " << h.backlog_dropped
           << ", not written " << h.not_written << '\n';
    }
    return os.str();
}

}  // namespace airseg::linksim
