#pragma once
// The rover's parameter table: names, types and defaults of an APM:Rover 2.x board. It stands for the
// board's EEPROM, so it survives simulated reboots.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/apmsim/firmware_profile.hpp"

namespace airseg::apmsim {

/// MAV_PARAM_TYPE values ArduPilot uses.
enum class ParamType : std::uint8_t { Int8 = 2, Int16 = 4, Int32 = 6, Real32 = 9 };

struct Param {
    std::string name;  // at most 16 characters (the PARAM_VALUE field)
    ParamType type = ParamType::Real32;
    float value = 0.0F;
};

class ParamTable {
  public:
    /// The table of a freshly flashed APM:Rover (a little over 250 parameters).
    static ParamTable rover_defaults();
    /// The table of a board running `profile`: rover_defaults(), and on a board with ArduPilot 4.x arming
    /// ARMING_REQUIRE 1, with AR_WPNav speeds WP_SPEED (2 m/s), with S-curve cornering ATC_ACCEL_MAX
    /// (1 m/s²) and ATC_TURN_MAX_G (0.6 g), the defaults of AR_WPNav.cpp and AR_AttitudeControl.cpp.
    static ParamTable for_profile(const FirmwareProfile& profile);

    std::size_t size() const { return params_.size(); }
    const Param& at(std::size_t index) const { return params_.at(index); }
    std::optional<std::size_t> index_of(std::string_view name) const;
    /// Value of a parameter the simulator itself relies on; `fallback` if it is absent.
    float get(std::string_view name, float fallback) const;
    /// Stores `value`, rounded and clamped to the parameter's integer type. Returns the index, or nothing
    /// for an unknown name or a value that is not a finite number.
    std::optional<std::size_t> set(std::string_view name, float value);

  private:
    void add(std::string name, ParamType type, float value);

    std::vector<Param> params_;
};

}  // namespace airseg::apmsim
