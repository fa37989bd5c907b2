#include "tools/apmsim/param_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace airseg::apmsim {

namespace {

constexpr auto I8 = ParamType::Int8;
constexpr auto I16 = ParamType::Int16;
constexpr auto I32 = ParamType::Int32;
constexpr auto F = ParamType::Real32;

struct Entry {
    const char* name;
    ParamType type;
    float value;
};

// Parameters and defaults of an APM 2.5 running APM:Rover 2.4x, grouped as the firmware declares them.
constexpr Entry kRover[] = {
    {"FORMAT_VERSION", I16, 16},
    {"SYSID_SW_TYPE", I16, 20},
    {"SYSID_THISMAV", I16, 1},
    {"SYSID_MYGCS", I16, 255},
    {"INITIAL_MODE", I8, 0},
    {"LOG_BITMASK", I16, 4950},
    {"RST_SWITCH_CH", I8, 0},
    {"TELEM_DELAY", I8, 0},
    {"GCS_PID_MASK", I16, 0},
    {"MAG_ENABLE", I16, 1},
    {"AUTO_TRIGGER_PIN", I8, -1},
    {"AUTO_KICKSTART", F, 0},
    {"CRUISE_SPEED", F, 2},
    {"SPEED_TURN_GAIN", I8, 50},
    {"SPEED_TURN_DIST", F, 2},
    {"BRAKING_PERCENT", I8, 0},
    {"BRAKING_SPEEDERR", F, 3},
    {"PIVOT_TURN_ANGLE", I16, 30},
    {"CH7_OPTION", I8, 1},
    {"THR_MIN", I8, 0},
    {"THR_MAX", I8, 100},
    {"CRUISE_THROTTLE", I8, 50},
    {"THR_SLEWRATE", I8, 0},
    {"SKID_STEER_OUT", I8, 0},
    {"SKID_STEER_IN", I8, 0},
    {"FS_ACTION", I8, 2},
    {"FS_TIMEOUT", F, 5},
    {"FS_THR_ENABLE", I8, 0},
    {"FS_THR_VALUE", I16, 910},
    {"FS_GCS_ENABLE", I8, 0},
    {"RNGFND_TRIGGR_CM", I16, 100},
    {"RNGFND_TURN_ANGL", F, 45},
    {"RNGFND_TURN_TIME", F, 1},
    {"RNGFND_DEBOUNCE", I8, 2},
    {"LEARN_CH", I8, 7},
    {"MODE_CH", I8, 8},
    {"MODE1", I8, 10},
    {"MODE2", I8, 10},
    {"MODE3", I8, 2},
    {"MODE4", I8, 2},
    {"MODE5", I8, 4},
    {"MODE6", I8, 0},
    {"WP_RADIUS", F, 2},
    {"TURN_MAX_G", F, 2},
    {"ARMING_REQUIRE", I8, 0},
    {"ARMING_CHECK", I8, 1},
    {"ARMING_DIS_RUD", I8, 0},
    {"NAVL1_PERIOD", F, 8},
    {"NAVL1_DAMPING", F, 0.75F},
    {"STEER2SRV_TCONST", F, 0.75F},
    {"STEER2SRV_P", F, 1.8F},
    {"STEER2SRV_I", F, 0.2F},
    {"STEER2SRV_D", F, 0.005F},
    {"STEER2SRV_IMAX", I16, 1500},
    {"STEER2SRV_MINSPD", F, 1},
    {"SPEED2THR_P", F, 0.7F},
    {"SPEED2THR_I", F, 0.2F},
    {"SPEED2THR_D", F, 0.2F},
    {"SPEED2THR_IMAX", I16, 4000},
    {"SERIAL0_BAUD", I16, 115},
    {"SERIAL1_BAUD", I16, 57},
    {"SERIAL2_BAUD", I16, 57},
    {"SERIAL2_PROTOCOL", I8, 1},
    {"INS_PRODUCT_ID", I16, 88},
    {"INS_ACCSCAL_X", F, 1},
    {"INS_ACCSCAL_Y", F, 1},
    {"INS_ACCSCAL_Z", F, 1},
    {"INS_ACCOFFS_X", F, 0},
    {"INS_ACCOFFS_Y", F, 0},
    {"INS_ACCOFFS_Z", F, 0},
    {"INS_GYROFFS_X", F, 0},
    {"INS_GYROFFS_Y", F, 0},
    {"INS_GYROFFS_Z", F, 0},
    {"INS_MPU6K_FILTER", I8, 0},
    {"COMPASS_OFS_X", F, 0},
    {"COMPASS_OFS_Y", F, 0},
    {"COMPASS_OFS_Z", F, 0},
    {"COMPASS_DEC", F, 0},
    {"COMPASS_LEARN", I8, 1},
    {"COMPASS_USE", I8, 1},
    {"COMPASS_AUTODEC", I8, 1},
    {"COMPASS_MOTCT", I8, 0},
    {"COMPASS_MOT_X", F, 0},
    {"COMPASS_MOT_Y", F, 0},
    {"COMPASS_MOT_Z", F, 0},
    {"COMPASS_ORIENT", I8, 0},
    {"COMPASS_EXTERNAL", I8, 0},
    {"AHRS_GPS_GAIN", F, 0},
    {"AHRS_GPS_USE", I8, 1},
    {"AHRS_YAW_P", F, 0.2F},
    {"AHRS_RP_P", F, 0.2F},
    {"AHRS_WIND_MAX", I8, 0},
    {"AHRS_TRIM_X", F, 0},
    {"AHRS_TRIM_Y", F, 0},
    {"AHRS_TRIM_Z", F, 0},
    {"AHRS_ORIENTATION", I8, 0},
    {"AHRS_COMP_BETA", F, 0.1F},
    {"AHRS_GPS_MINSATS", I8, 6},
    {"AHRS_EKF_USE", I8, 0},
    {"BATT_MONITOR", I8, 4},
    {"BATT_VOLT_PIN", I8, 1},
    {"BATT_CURR_PIN", I8, 2},
    {"BATT_VOLT_MULT", F, 10.1F},
    {"BATT_AMP_PERVOLT", F, 17},
    {"BATT_AMP_OFFSET", F, 0},
    {"BATT_CAPACITY", I32, 3300},
    {"BATT_VOLT2_PIN", I8, -1},
    {"BATT_VOLT2_MULT", F, 1},
    {"GND_ABS_PRESS", F, 101325},
    {"GND_TEMP", F, 21},
    {"GND_ALT_OFFSET", I8, 0},
    {"GPS_TYPE", I8, 1},
    {"GPS_NAVFILTER", I8, 8},
    {"GPS_AUTO_SWITCH", I8, 1},
    {"GPS_MIN_DGPS", I8, 100},
    {"GPS_SBAS_MODE", I8, 2},
    {"GPS_MIN_ELEV", I8, -100},
    {"RELAY_PIN", I8, 13},
    {"RELAY_PIN2", I8, -1},
    {"RELAY_DEFAULT", I8, 0},
    {"RNGFND_TYPE", I8, 0},
    {"RNGFND_PIN", I8, -1},
    {"RNGFND_SCALING", F, 3},
    {"RNGFND_OFFSET", F, 0},
    {"RNGFND_FUNCTION", I8, 0},
    {"RNGFND_MIN_CM", I16, 20},
    {"RNGFND_MAX_CM", I16, 700},
    {"RNGFND_STOP_PIN", I8, -1},
    {"RNGFND_SETTLE_MS", I16, 0},
    {"RNGFND_RMETRIC", I8, 1},
    {"RNGFND2_TYPE", I8, 0},
    {"RNGFND2_PIN", I8, -1},
    {"RNGFND2_SCALING", F, 3},
    {"RNGFND2_OFFSET", F, 0},
    {"RNGFND2_FUNCTION", I8, 0},
    {"RNGFND2_MIN_CM", I16, 20},
    {"RNGFND2_MAX_CM", I16, 700},
    {"CAM_TRIGG_TYPE", I8, 0},
    {"CAM_DURATION", I8, 10},
    {"CAM_SERVO_ON", I16, 1300},
    {"CAM_SERVO_OFF", I16, 1100},
    {"CAM_TRIGG_DIST", F, 0},
    {"MNT_MODE", I8, 3},
    {"MNT_RETRACT_X", F, 0},
    {"MNT_RETRACT_Y", F, 0},
    {"MNT_RETRACT_Z", F, 0},
    {"MNT_NEUTRAL_X", F, 0},
    {"MNT_NEUTRAL_Y", F, 0},
    {"MNT_NEUTRAL_Z", F, 0},
    {"MNT_CONTROL_X", F, 0},
    {"MNT_CONTROL_Y", F, 0},
    {"MNT_CONTROL_Z", F, 0},
    {"MNT_STAB_ROLL", I8, 0},
    {"MNT_STAB_TILT", I8, 0},
    {"MNT_STAB_PAN", I8, 0},
    {"MNT_RC_IN_ROLL", I8, 0},
    {"MNT_RC_IN_TILT", I8, 0},
    {"MNT_RC_IN_PAN", I8, 0},
    {"MNT_JSTICK_SPD", I8, 0},
    {"SCHED_DEBUG", I8, 0},
    {"MIS_TOTAL", I16, 0},
    {"MIS_RESTART", I8, 0},
    {"RSSI_PIN", I8, -1},
    {"RSSI_RANGE", F, 5},
    {"BRD_PWM_COUNT", I8, 4},
    {"SYSID_SW_MREV", I16, 120},
    {"SONAR_ENABLE", I8, 0},
    {"SR0_RAW_SENS", I16, 0},
    {"LOG_FILE_BUFSIZE", I8, 16},
    {"EKF_GPS_TYPE", I8, 0},
    {"EKF_VELNE_NOISE", F, 0.5F},
    {"EKF_VELD_NOISE", F, 0.7F},
    {"EKF_POSNE_NOISE", F, 0.5F},
    {"EKF_ALT_NOISE", F, 1},
    {"EKF_MAG_NOISE", F, 0.05F},
    {"EKF_EAS_NOISE", F, 1.4F},
    {"EKF_WIND_PNOISE", F, 0.1F},
    {"EKF_WIND_PSCALE", F, 0.5F},
    {"EKF_GYRO_PNOISE", F, 0.015F},
    {"EKF_ACC_PNOISE", F, 0.25F},
    {"EKF_GBIAS_PNOISE", F, 1e-6F},
    {"EKF_ABIAS_PNOISE", F, 2e-4F},
    {"EKF_MAGE_PNOISE", F, 3e-4F},
    {"EKF_MAGB_PNOISE", F, 3e-4F},
    {"EKF_VEL_DELAY", I8, 220},
    {"EKF_POS_DELAY", I8, 220},
    {"EKF_GLITCH_ACCEL", F, 150},
    {"EKF_GLITCH_RAD", I8, 15},
    {"EKF_GND_GRADIENT", I8, 2},
    {"EKF_FLOW_NOISE", F, 0.3F},
    {"EKF_FLOW_GATE", I16, 300},
    {"EKF_FLOW_DELAY", I8, 25},
    {"EKF_GPS_CHECK", I8, 1},
    {"EKF_VEL_GATE", I16, 500},
    {"EKF_POS_GATE", I16, 500},
    {"EKF_HGT_GATE", I16, 500},
    {"EKF_MAG_GATE", I16, 300},
    {"EKF_EAS_GATE", I16, 400},
    {"EKF_MAG_CAL", I8, 1},
    {"EKF_RNG_GATE", I16, 500},
    {"EKF_MAX_FLOW", F, 2.5F},
    {"EKF_FALLBACK", I8, 1},
    {"EKF_ALT_SOURCE", I8, 0},
    {"FENCE_ACTION", I8, 0},
    {"FENCE_TOTAL", I8, 0},
    {"RC_OVERRIDE_TIME", F, 3},
    {"RCMAP_ROLL", I8, 1},
    {"RCMAP_PITCH", I8, 2},
    {"RCMAP_THROTTLE", I8, 3},
    {"RCMAP_YAW", I8, 4},
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
            t.add("SR" + std::to_string(port) + "_" + suffix, I16, rate);
        }
    }
    for (int ch = 1; ch <= 8; ++ch) {
        const std::string p = "RC" + std::to_string(ch) + "_";
        t.add(p + "MIN", I16, 1100);
        t.add(p + "TRIM", I16, 1500);
        t.add(p + "MAX", I16, 1900);
        t.add(p + "REV", I8, 1);
        t.add(p + "DZ", I16, ch == 1 || ch == 3 ? 30 : 0);
        if (ch >= 5) {
            t.add(p + "FUNCTION", I8, 0);
        }
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
