#include "tools/apmsim/firmware_profile.hpp"

#include <cctype>
#include <string>

namespace airseg::apmsim {

std::string_view firmware_name(Firmware f) {
    switch (f) {
        case Firmware::Modern:
            return "modern";
        case Firmware::Rover2:
            return "rover2";
    }
    return "?";
}

std::optional<Firmware> parse_firmware(std::string_view text) {
    std::string lower(text);
    for (char& c : lower) {
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    for (Firmware f : {Firmware::Modern, Firmware::Rover2}) {
        if (lower == firmware_name(f)) {
            return f;
        }
    }
    return std::nullopt;
}

FirmwareProfile FirmwareProfile::modern() {
    return FirmwareProfile{};
}

FirmwareProfile FirmwareProfile::rover2() {
    FirmwareProfile p;
    p.firmware = Firmware::Rover2;
    p.reads_mavlink2 = false;
    p.mission_int = false;
    p.broadcast_target = false;
    p.mission = Dialect::Rover2;
    p.commands = Dialect::Rover2;
    p.telemetry = Dialect::Rover2;
    p.change_speed_command = false;
    p.arming_checks = false;
    p.mission_change_restart = false;
    p.auto_speed = AutoSpeed::CruiseSpeed;
    p.cornering = false;
    return p;
}

FirmwareProfile FirmwareProfile::of(Firmware f) {
    return f == Firmware::Rover2 ? rover2() : modern();
}

}  // namespace airseg::apmsim
