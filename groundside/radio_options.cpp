#include "groundside/radio_options.hpp"

#include <climits>
#include <string>

namespace airseg::groundside {

void add_radio_options(cli::OptionTable& table, RadioOptions& radio, std::function<void()> chosen) {
    using namespace airseg::cli;
    table
        .value("link", "PATH[,PATH2]",
               "over the ground radio(s) on these serial devices; with two, list them in the same radio-pair "
               "order as the vehicle's groundlink.ports",
               [&radio, chosen](std::string_view option, std::string_view v) {
                   if (v.empty()) {
                       throw UsageError(std::string(option) + ": expected PATH[,PATH2], got ''");
                   }
                   radio.ports.clear();
                   std::size_t start = 0;
                   for (std::size_t comma; (comma = v.find(',', start)) != std::string_view::npos;
                        start = comma + 1) {
                       radio.ports.emplace_back(v.substr(start, comma - start));
                   }
                   radio.ports.emplace_back(v.substr(start));
                   if (radio.ports.size() == 2 && radio.mode == "single") {
                       radio.mode = "split";
                   }
                   chosen();
               })
        .value("udp", "HOST:PORT", "over UDP to the vehicle's ground-link socket",
               [&radio, chosen](std::string_view, std::string_view v) {
                   radio.udp = v;
                   chosen();
               })
        .value("baud", "N", "radio port baud rate (default 57600)", number(radio.baud, 0, UINT32_MAX))
        .value("mode", "MODE", "single (one device), split or redundant (two devices)", text(radio.mode))
        .value("key", "FILE",
               "pre-shared key file (mode 0600), the same as the vehicle's groundlink.key_file",
               text(radio.key_file))
        .value("radio", "KEY=VALUE[,...]",
               "the radios' air, the same as the vehicle's groundlink.radio (serial links only): air_speed "
               "(kbit/s, 0 = the serial rate), ecc (on|off), packet, packet_overhead, buffer (bytes), "
               "turnaround (e.g. 10ms), duplex (half|full); repeatable, a key given again wins",
               [&radio](std::string_view, std::string_view v) {
                   if (auto error = groundlink::parse_radio_profile(v, radio.profile); !error.empty()) {
                       throw UsageError(error);
                   }
                   radio.profile_given = true;
               });
}

}  // namespace airseg::groundside
