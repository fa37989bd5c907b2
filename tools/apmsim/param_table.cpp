#include "tools/apmsim/param_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace airseg::apmsim {

namespace {

using enum ParamType;

struct Entry {
    const char* name;
    ParamType type;
    float value;
};

// Parameters and defaults of an APM 2.5 running APM:Rover 2.4x, grouped as the firmware declares them.
constexpr Entry kRover[] = {
    {"FORMAT_VERSION", Int16, 16},
    {"SYSID_SW_TYPE", Int16, 20},
    {"SYSID_THISMAV", Int16, 1},
    {"SYSID_MYGCS", Int16, 255},
    {"INITIAL_MODE", Int8, 0},
    {"LOG_BITMASK", Int16, 4950},
    {"RST_SWITCH_CH", Int8, 0},
    {"TELEM_DELAY", Int8, 0},
    {"GCS_PID_MASK", Int16, 0},
    {"MAG_ENABLE", Int16, 1},
    {"AUTO_TRIGGER_PIN", Int8, -1},
    {"AUTO_KICKSTART", Real32, 0},
    {"CRUISE_SPEED", Real32, 2},
    {"SPEED_TURN_GAIN", Int8, 50},
    {"SPEED_TURN_DIST", Real32, 2},
    {"BRAKING_PERCENT", Int8, 0},
    {"BRAKING_SPEEDERR", Real32, 3},
    {"PIVOT_TURN_ANGLE", Int16, 30},
    {"CH7_OPTION", Int8, 1},
    {"THR_MIN", Int8, 0},
    {"THR_MAX", Int8, 100},
    {"CRUISE_THROTTLE", Int8, 50},
    {"THR_SLEWRATE", Int8, 0},
    {"SKID_STEER_OUT", Int8, 0},
    {"SKID_STEER_IN", Int8, 0},
    {"FS_ACTION", Int8, 2},
    {"FS_TIMEOUT", Real32, 5},
    {"FS_THR_ENABLE", Int8, 0},
    {"FS_THR_VALUE", Int16, 910},
    {"FS_GCS_ENABLE", Int8, 0},
    {"RNGFND_TRIGGR_CM", Int16, 100},
    {"RNGFND_TURN_ANGL", Real32, 45},
    {"RNGFND_TURN_TIME", Real32, 1},
    {"RNGFND_DEBOUNCE", Int8, 2},
    {"LEARN_CH", Int8, 7},
    {"MODE_CH", Int8, 8},
    {"MODE1", Int8, 10},
    {"MODE2", Int8, 10},
    {"MODE3", Int8, 2},
    {"MODE4", Int8, 2},
    {"MODE5", Int8, 4},
    {"MODE6", Int8, 0},
    {"WP_RADIUS", Real32, 2},
    {"TURN_MAX_G", Real32, 2},
    {"ARMING_REQUIRE", Int8, 0},
    {"ARMING_CHECK", Int8, 1},
    {"ARMING_DIS_RUD", Int8, 0},
    {"NAVL1_PERIOD", Real32, 8},
    {"NAVL1_DAMPING", Real32, 0.75F},
    {"STEER2SRV_TCONST", Real32, 0.75F},
    {"STEER2SRV_P", Real32, 1.8F},
    {"STEER2SRV_I", Real32, 0.2F},
    {"STEER2SRV_D", Real32, 0.005F},
    {"STEER2SRV_IMAX", Int16, 1500},
    {"STEER2SRV_MINSPD", Real32, 1},
    {"SPEED2THR_P", Real32, 0.7F},
    {"SPEED2THR_I", Real32, 0.2F},
    {"SPEED2THR_D", Real32, 0.2F},
    {"SPEED2THR_IMAX", Int16, 4000},
    {"SERIAL0_BAUD", Int16, 115},
    {"SERIAL1_BAUD", Int16, 57},
    {"SERIAL2_BAUD", Int16, 57},
    {"SERIAL2_PROTOCOL", Int8, 1},
    {"INS_PRODUCT_ID", Int16, 88},
    {"INS_ACCSCAL_X", Real32, 1},
    {"INS_ACCSCAL_Y", Real32, 1},
    {"INS_ACCSCAL_Z", Real32, 1},
    {"INS_ACCOFFS_X", Real32, 0},
    {"INS_ACCOFFS_Y", Real32, 0},
    {"INS_ACCOFFS_Z", Real32, 0},
    {"INS_GYROFFS_X", Real32, 0},
    {"INS_GYROFFS_Y", Real32, 0},
    {"INS_GYROFFS_Z", Real32, 0},
    {"INS_MPU6K_FILTER", Int8, 0},
    {"COMPASS_OFS_X", Real32, 0},
    {"COMPASS_OFS_Y", Real32, 0},
    {"COMPASS_OFS_Z", Real32, 0},
    {"COMPASS_DEC", Real32, 0},
    {"COMPASS_LEARN", Int8, 1},
    {"COMPASS_USE", Int8, 1},
    {"COMPASS_AUTODEC", Int8, 1},
    {"COMPASS_MOTCT", Int8, 0},
    {"COMPASS_MOT_X", Real32, 0},
    {"COMPASS_MOT_Y", Real32, 0},
    {"COMPASS_MOT_Z", Real32, 0},
    {"COMPASS_ORIENT", Int8, 0},
    {"COMPASS_EXTERNAL", Int8, 0},
    {"AHRS_GPS_GAIN", Real32, 0},
    {"AHRS_GPS_USE", Int8, 1},
    {"AHRS_YAW_P", Real32, 0.2F},
    {"AHRS_RP_P", Real32, 0.2F},
    {"AHRS_WIND_MAX", Int8, 0},
    {"AHRS_TRIM_X", Real32, 0},
    {"AHRS_TRIM_Y", Real32, 0},
    {"AHRS_TRIM_Z", Real32, 0},
    {"AHRS_ORIENTATION", Int8, 0},
    {"AHRS_COMP_BETA", Real32, 0.1F},
    {"AHRS_GPS_MINSATS", Int8, 6},
    {"AHRS_EKF_USE", Int8, 0},
    {"BATT_MONITOR", Int8, 4},
    {"BATT_VOLT_PIN", Int8, 1},
    {"BATT_CURR_PIN", Int8, 2},
    {"BATT_VOLT_MULT", Real32, 10.1F},
    {"BATT_AMP_PERVOLT", Real32, 17},
    {"BATT_AMP_OFFSET", Real32, 0},
    {"BATT_CAPACITY", Int32, 3300},
    {"BATT_VOLT2_PIN", Int8, -1},
    {"BATT_VOLT2_MULT", Real32, 1},
    {"GND_ABS_PRESS", Real32, 101325},
    {"GND_TEMP", Real32, 21},
    {"GND_ALT_OFFSET", Int8, 0},
    {"GPS_TYPE", Int8, 1},
    {"GPS_NAVFILTER", Int8, 8},
    {"GPS_AUTO_SWITCH", Int8, 1},
    {"GPS_MIN_DGPS", Int8, 100},
    {"GPS_SBAS_MODE", Int8, 2},
    {"GPS_MIN_ELEV", Int8, -100},
    {"RELAY_PIN", Int8, 13},
    {"RELAY_PIN2", Int8, -1},
    {"RELAY_DEFAULT", Int8, 0},
    {"RNGFND_TYPE", Int8, 0},
    {"RNGFND_PIN", Int8, -1},
    {"RNGFND_SCALING", Real32, 3},
    {"RNGFND_OFFSET", Real32, 0},
    {"RNGFND_FUNCTION", Int8, 0},
    {"RNGFND_MIN_CM", Int16, 20},
    {"RNGFND_MAX_CM", Int16, 700},
    {"RNGFND_STOP_PIN", Int8, -1},
    {"RNGFND_SETTLE_MS", Int16, 0},
    {"RNGFND_RMETRIC", Int8, 1},
    {"RNGFND2_TYPE", Int8, 0},
    {"RNGFND2_PIN", Int8, -1},
    {"RNGFND2_SCALING", Real32, 3},
    {"RNGFND2_OFFSET", Real32, 0},
    {"RNGFND2_FUNCTION", Int8, 0},
    {"RNGFND2_MIN_CM", Int16, 20},
    {"RNGFND2_MAX_CM", Int16, 700},
    {"CAM_TRIGG_TYPE", Int8, 0},
    {"CAM_DURATION", Int8, 10},
    {"CAM_SERVO_ON", Int16, 1300},
    {"CAM_SERVO_OFF", Int16, 1100},
    {"CAM_TRIGG_DIST", Real32, 0},
    {"MNT_MODE", Int8, 3},
    {"MNT_RETRACT_X", Real32, 0},
    {"MNT_RETRACT_Y", Real32, 0},
    {"MNT_RETRACT_Z", Real32, 0},
    {"MNT_NEUTRAL_X", Real32, 0},
    {"MNT_NEUTRAL_Y", Real32, 0},
    {"MNT_NEUTRAL_Z", Real32, 0},
    {"MNT_CONTROL_X", Real32, 0},
    {"MNT_CONTROL_Y", Real32, 0},
    {"MNT_CONTROL_Z", Real32, 0},
    {"MNT_STAB_ROLL", Int8, 0},
    {"MNT_STAB_TILT", Int8, 0},
    {"MNT_STAB_PAN", Int8, 0},
    {"MNT_RC_IN_ROLL", Int8, 0},
    {"MNT_RC_IN_TILT", Int8, 0},
    {"MNT_RC_IN_PAN", Int8, 0},
    {"MNT_JSTICK_SPD", Int8, 0},
    {"SCHED_DEBUG", Int8, 0},
    {"MIS_TOTAL", Int16, 0},
    {"MIS_RESTART", Int8, 0},
    {"RSSI_PIN", Int8, -1},
    {"RSSI_RANGE", Real32, 5},
    {"BRD_PWM_COUNT", Int8, 4},
    {"SYSID_SW_MREV", Int16, 120},
    {"SONAR_ENABLE", Int8, 0},
    {"SR0_RAW_SENS", Int16, 0},
    {"LOG_FILE_BUFSIZE", Int8, 16},
    {"EKF_GPS_TYPE", Int8, 0},
    {"EKF_VELNE_NOISE", Real32, 0.5F},
    {"EKF_VELD_NOISE", Real32, 0.7F},
    {"EKF_POSNE_NOISE", Real32, 0.5F},
    {"EKF_ALT_NOISE", Real32, 1},
    {"EKF_MAG_NOISE", Real32, 0.05F},
    {"EKF_EAS_NOISE", Real32, 1.4F},
    {"EKF_WIND_PNOISE", Real32, 0.1F},
    {"EKF_WIND_PSCALE", Real32, 0.5F},
    {"EKF_GYRO_PNOISE", Real32, 0.015F},
    {"EKF_ACC_PNOISE", Real32, 0.25F},
    {"EKF_GBIAS_PNOISE", Real32, 1e-6F},
    {"EKF_ABIAS_PNOISE", Real32, 2e-4F},
    {"EKF_MAGE_PNOISE", Real32, 3e-4F},
    {"EKF_MAGB_PNOISE", Real32, 3e-4F},
    {"EKF_VEL_DELAY", Int16, 220},  // AP_Int16 in NavEKF: 220 ms does not fit an Int8
    {"EKF_POS_DELAY", Int16, 220},
    {"EKF_GLITCH_ACCEL", Real32, 150},
    {"EKF_GLITCH_RAD", Int8, 15},
    {"EKF_GND_GRADIENT", Int8, 2},
    {"EKF_FLOW_NOISE", Real32, 0.3F},
    {"EKF_FLOW_GATE", Int16, 300},
    {"EKF_FLOW_DELAY", Int8, 25},
    {"EKF_GPS_CHECK", Int8, 1},
    {"EKF_VEL_GATE", Int16, 500},
    {"EKF_POS_GATE", Int16, 500},
    {"EKF_HGT_GATE", Int16, 500},
    {"EKF_MAG_GATE", Int16, 300},
    {"EKF_EAS_GATE", Int16, 400},
    {"EKF_MAG_CAL", Int8, 1},
    {"EKF_RNG_GATE", Int16, 500},
    {"EKF_MAX_FLOW", Real32, 2.5F},
    {"EKF_FALLBACK", Int8, 1},
    {"EKF_ALT_SOURCE", Int8, 0},
    {"FENCE_ACTION", Int8, 0},
    {"FENCE_TOTAL", Int8, 0},
    {"RC_OVERRIDE_TIME", Real32, 3},
    {"RCMAP_ROLL", Int8, 1},
    {"RCMAP_PITCH", Int8, 2},
    {"RCMAP_THROTTLE", Int8, 3},
    {"RCMAP_YAW", Int8, 4},
};

// Stream rates per serial port, in Hz, as REQUEST_DATA_STREAM stores them.
constexpr const char* kStreamSuffixes[] = {"RAW_SENS", "EXT_STAT", "RC_CHAN", "RAW_CTRL", "POSITION",
                                           "EXTRA1",   "EXTRA2",   "EXTRA3",  "PARAMS"};

}  // namespace

ParamTable ParamTable::rover_defaults() {
    ParamTable t;
    for (const Entry& e : kRover) {
        if (std::string_view(e.name) != "SR0_RAW_SENS") {  // added with its group below
            t.add(e.name, e.type, e.value);
        }
    }
    for (int port = 0; port < 3; ++port) {
        for (const char* suffix : kStreamSuffixes) {
            const float rate = std::string_view(suffix) == "PARAMS" ? 10.0F : 0.0F;
            t.add("SR" + std::to_string(port) + "_" + suffix, Int16, rate);
        }
    }
    for (int ch = 1; ch <= 8; ++ch) {
        const std::string p = "RC" + std::to_string(ch) + "_";
        t.add(p + "MIN", Int16, 1100);
        t.add(p + "TRIM", Int16, 1500);
        t.add(p + "MAX", Int16, 1900);
        t.add(p + "REV", Int8, 1);
        t.add(p + "DZ", Int16, ch == 1 || ch == 3 ? 30 : 0);
        if (ch >= 5) {
            t.add(p + "FUNCTION", Int8, 0);
        }
    }
    return t;
}

ParamTable ParamTable::for_profile(const FirmwareProfile& profile) {
    ParamTable t = rover_defaults();
    if (profile.arming_checks) {
        t.set("ARMING_REQUIRE", 1);  // AP_Arming: Required::YES_MIN_PWM
    }
    if (profile.auto_speed == FirmwareProfile::AutoSpeed::WpSpeed) {
        t.add("WP_SPEED", Real32, 2);  // AR_WPNAV_SPEED_DEFAULT
    }
    if (profile.cornering) {
        t.add("ATC_ACCEL_MAX", Real32, 1);      // AR_ATTCONTROL_THR_ACCEL_MAX
        t.add("ATC_TURN_MAX_G", Real32, 0.6F);  // AR_AttitudeControl _TURN_MAX_G
    }
    return t;
}

void ParamTable::add(std::string name, ParamType type, float value) {
    params_.push_back(Param{std::move(name), type, value});
}

std::optional<std::size_t> ParamTable::index_of(std::string_view name) const {
    const auto it =
        std::find_if(params_.begin(), params_.end(), [&](const Param& p) { return p.name == name; });
    if (it == params_.end()) {
        return std::nullopt;
    }
    return static_cast<std::size_t>(it - params_.begin());
}

float ParamTable::get(std::string_view name, float fallback) const {
    const auto i = index_of(name);
    return i ? params_[*i].value : fallback;
}

std::optional<std::size_t> ParamTable::set(std::string_view name, float value) {
    const auto i = index_of(name);
    if (!i || !std::isfinite(value)) {
        return std::nullopt;
    }
    Param& p = params_[*i];
    switch (p.type) {
        case ParamType::Int8:
            p.value = std::clamp(std::round(value), -128.0F, 127.0F);
            break;
        case ParamType::Int16:
            p.value = std::clamp(std::round(value), -32768.0F, 32767.0F);
            break;
        case ParamType::Int32:
            p.value = std::clamp(std::round(value), -2147483648.0F, 2147483520.0F);
            break;
        case ParamType::Real32:
            p.value = value;
            break;
    }
    return i;
}

}  // namespace airseg::apmsim
