// ArduPilot's whole dialect (dialect.def, dialect_table.cpp): the CRC_EXTRA and lengths derived from the
// table against published values, and the typed messages of messages.def against the table.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::mavlink {
// Named: a unity build compiles the test files of this binary in one translation unit.
namespace dialect_test {
namespace {

struct Published {
    std::uint32_t id;
    std::string_view name;
    std::uint8_t crc_extra;
    std::uint8_t min_length;  // the base fields
    std::uint8_t max_length;  // all fields
};

// Published by node-mavlink 2.3.0 (its mavlink-mappings package, the version pinned in
// tests/integration/mavlink_interop/package-lock.json): MSG_ID, MSG_NAME, MAGIC_NUMBER (CRC_EXTRA),
// PAYLOAD_LENGTH and the sum of its non-extension FIELDS, for every dialect id it defines except 296: there
// it has GLOBAL_POSITION of an older development.xml, since redefined as GLOBAL_POSITION_SENSOR.
// clang-format off
constexpr Published kNodeMavlink[] = {
    {0, "HEARTBEAT", 50, 9, 9},
    {1, "SYS_STATUS", 124, 31, 43},
    {2, "SYSTEM_TIME", 137, 12, 12},
    {4, "PING", 237, 14, 14},
    {5, "CHANGE_OPERATOR_CONTROL", 217, 28, 28},
    {6, "CHANGE_OPERATOR_CONTROL_ACK", 104, 3, 3},
    {7, "AUTH_KEY", 119, 32, 32},
    {11, "SET_MODE", 89, 6, 6},
    {20, "PARAM_REQUEST_READ", 214, 20, 20},
    {21, "PARAM_REQUEST_LIST", 159, 2, 2},
    {22, "PARAM_VALUE", 220, 25, 25},
    {23, "PARAM_SET", 168, 23, 23},
    {24, "GPS_RAW_INT", 24, 30, 52},
    {25, "GPS_STATUS", 23, 101, 101},
    {26, "SCALED_IMU", 170, 22, 24},
    {27, "RAW_IMU", 144, 26, 29},
    {28, "RAW_PRESSURE", 67, 16, 16},
    {29, "SCALED_PRESSURE", 115, 14, 16},
    {30, "ATTITUDE", 39, 28, 28},
    {31, "ATTITUDE_QUATERNION", 246, 32, 48},
    {32, "LOCAL_POSITION_NED", 185, 28, 28},
    {33, "GLOBAL_POSITION_INT", 104, 28, 28},
    {34, "RC_CHANNELS_SCALED", 237, 22, 22},
    {35, "RC_CHANNELS_RAW", 244, 22, 22},
    {36, "SERVO_OUTPUT_RAW", 222, 21, 37},
    {37, "MISSION_REQUEST_PARTIAL_LIST", 212, 6, 7},
    {38, "MISSION_WRITE_PARTIAL_LIST", 9, 6, 7},
    {39, "MISSION_ITEM", 254, 37, 38},
    {40, "MISSION_REQUEST", 230, 4, 5},
    {41, "MISSION_SET_CURRENT", 28, 4, 4},
    {42, "MISSION_CURRENT", 28, 2, 18},
    {43, "MISSION_REQUEST_LIST", 132, 2, 3},
    {44, "MISSION_COUNT", 221, 4, 9},
    {45, "MISSION_CLEAR_ALL", 232, 2, 3},
    {46, "MISSION_ITEM_REACHED", 11, 2, 2},
    {47, "MISSION_ACK", 153, 3, 8},
    {48, "SET_GPS_GLOBAL_ORIGIN", 41, 13, 21},
    {49, "GPS_GLOBAL_ORIGIN", 39, 12, 20},
    {50, "PARAM_MAP_RC", 78, 37, 37},
    {51, "MISSION_REQUEST_INT", 196, 4, 5},
    {54, "SAFETY_SET_ALLOWED_AREA", 15, 27, 27},
    {55, "SAFETY_ALLOWED_AREA", 3, 25, 25},
    {61, "ATTITUDE_QUATERNION_COV", 167, 72, 72},
    {62, "NAV_CONTROLLER_OUTPUT", 183, 26, 26},
    {63, "GLOBAL_POSITION_INT_COV", 119, 181, 181},
    {64, "LOCAL_POSITION_NED_COV", 191, 225, 225},
    {65, "RC_CHANNELS", 118, 42, 42},
    {66, "REQUEST_DATA_STREAM", 148, 6, 6},
    {67, "DATA_STREAM", 21, 4, 4},
    {69, "MANUAL_CONTROL", 243, 11, 30},
    {70, "RC_CHANNELS_OVERRIDE", 124, 18, 38},
    {73, "MISSION_ITEM_INT", 38, 37, 38},
    {74, "VFR_HUD", 20, 20, 20},
    {75, "COMMAND_INT", 158, 35, 35},
    {76, "COMMAND_LONG", 152, 33, 33},
    {77, "COMMAND_ACK", 143, 3, 10},
    {81, "MANUAL_SETPOINT", 106, 22, 22},
    {82, "SET_ATTITUDE_TARGET", 49, 39, 51},
    {83, "ATTITUDE_TARGET", 22, 37, 37},
    {84, "SET_POSITION_TARGET_LOCAL_NED", 143, 53, 53},
    {85, "POSITION_TARGET_LOCAL_NED", 140, 51, 51},
    {86, "SET_POSITION_TARGET_GLOBAL_INT", 5, 53, 53},
    {87, "POSITION_TARGET_GLOBAL_INT", 150, 51, 51},
    {89, "LOCAL_POSITION_NED_SYSTEM_GLOBAL_OFFSET", 231, 28, 28},
    {90, "HIL_STATE", 183, 56, 56},
    {91, "HIL_CONTROLS", 63, 42, 42},
    {92, "HIL_RC_INPUTS_RAW", 54, 33, 33},
    {93, "HIL_ACTUATOR_CONTROLS", 47, 81, 81},
    {100, "OPTICAL_FLOW", 175, 26, 34},
    {101, "GLOBAL_VISION_POSITION_ESTIMATE", 102, 32, 117},
    {102, "VISION_POSITION_ESTIMATE", 158, 32, 117},
    {103, "VISION_SPEED_ESTIMATE", 208, 20, 57},
    {104, "VICON_POSITION_ESTIMATE", 56, 32, 116},
    {105, "HIGHRES_IMU", 93, 62, 63},
    {106, "OPTICAL_FLOW_RAD", 138, 44, 44},
    {107, "HIL_SENSOR", 108, 64, 65},
    {108, "SIM_STATE", 32, 84, 92},
    {109, "RADIO_STATUS", 185, 9, 9},
    {110, "FILE_TRANSFER_PROTOCOL", 84, 254, 254},
    {111, "TIMESYNC", 34, 16, 18},
    {112, "CAMERA_TRIGGER", 174, 12, 12},
    {113, "HIL_GPS", 124, 36, 39},
    {114, "HIL_OPTICAL_FLOW", 237, 44, 44},
    {115, "HIL_STATE_QUATERNION", 4, 64, 64},
    {116, "SCALED_IMU2", 76, 22, 24},
    {117, "LOG_REQUEST_LIST", 128, 6, 6},
    {118, "LOG_ENTRY", 56, 14, 14},
    {119, "LOG_REQUEST_DATA", 116, 12, 12},
    {120, "LOG_DATA", 134, 97, 97},
    {121, "LOG_ERASE", 237, 2, 2},
    {122, "LOG_REQUEST_END", 203, 2, 2},
    {123, "GPS_INJECT_DATA", 250, 113, 113},
    {124, "GPS2_RAW", 87, 35, 57},
    {125, "POWER_STATUS", 203, 6, 6},
    {126, "SERIAL_CONTROL", 220, 79, 81},
    {127, "GPS_RTK", 25, 35, 35},
    {128, "GPS2_RTK", 226, 35, 35},
    {129, "SCALED_IMU3", 46, 22, 24},
    {130, "DATA_TRANSMISSION_HANDSHAKE", 29, 13, 13},
    {131, "ENCAPSULATED_DATA", 223, 255, 255},
    {132, "DISTANCE_SENSOR", 85, 14, 39},
    {133, "TERRAIN_REQUEST", 6, 18, 18},
    {134, "TERRAIN_DATA", 229, 43, 43},
    {135, "TERRAIN_CHECK", 203, 8, 8},
    {136, "TERRAIN_REPORT", 1, 22, 22},
    {137, "SCALED_PRESSURE2", 195, 14, 16},
    {138, "ATT_POS_MOCAP", 109, 36, 120},
    {139, "SET_ACTUATOR_CONTROL_TARGET", 168, 43, 43},
    {140, "ACTUATOR_CONTROL_TARGET", 181, 41, 41},
    {141, "ALTITUDE", 47, 32, 32},
    {142, "RESOURCE_REQUEST", 72, 243, 243},
    {143, "SCALED_PRESSURE3", 131, 14, 16},
    {144, "FOLLOW_TARGET", 127, 93, 93},
    {146, "CONTROL_SYSTEM_STATE", 103, 100, 100},
    {147, "BATTERY_STATUS", 154, 36, 54},
    {148, "AUTOPILOT_VERSION", 178, 60, 78},
    {149, "LANDING_TARGET", 200, 30, 60},
    {150, "SENSOR_OFFSETS", 134, 42, 42},
    {151, "SET_MAG_OFFSETS", 219, 8, 8},
    {152, "MEMINFO", 208, 4, 8},
    {153, "AP_ADC", 188, 12, 12},
    {154, "DIGICAM_CONFIGURE", 84, 15, 15},
    {155, "DIGICAM_CONTROL", 22, 13, 13},
    {156, "MOUNT_CONFIGURE", 19, 6, 6},
    {157, "MOUNT_CONTROL", 21, 15, 15},
    {158, "MOUNT_STATUS", 134, 14, 15},
    {160, "FENCE_POINT", 78, 12, 12},
    {161, "FENCE_FETCH_POINT", 68, 3, 3},
    {162, "FENCE_STATUS", 189, 8, 9},
    {163, "AHRS", 127, 28, 28},
    {164, "SIMSTATE", 154, 44, 44},
    {165, "HWSTATUS", 21, 3, 3},
    {166, "RADIO", 21, 9, 9},
    {167, "LIMITS_STATUS", 144, 22, 22},
    {168, "WIND", 1, 12, 12},
    {169, "DATA16", 234, 18, 18},
    {170, "DATA32", 73, 34, 34},
    {171, "DATA64", 181, 66, 66},
    {172, "DATA96", 22, 98, 98},
    {173, "RANGEFINDER", 83, 8, 8},
    {174, "AIRSPEED_AUTOCAL", 167, 48, 48},
    {175, "RALLY_POINT", 138, 19, 19},
    {176, "RALLY_FETCH_POINT", 234, 3, 3},
    {177, "COMPASSMOT_STATUS", 240, 20, 20},
    {178, "AHRS2", 47, 24, 24},
    {179, "CAMERA_STATUS", 189, 29, 29},
    {180, "CAMERA_FEEDBACK", 52, 45, 47},
    {181, "BATTERY2", 174, 4, 4},
    {182, "AHRS3", 229, 40, 40},
    {183, "AUTOPILOT_VERSION_REQUEST", 85, 2, 2},
    {184, "REMOTE_LOG_DATA_BLOCK", 159, 206, 206},
    {185, "REMOTE_LOG_BLOCK_STATUS", 186, 7, 7},
    {186, "LED_CONTROL", 72, 29, 29},
    {191, "MAG_CAL_PROGRESS", 92, 27, 27},
    {192, "MAG_CAL_REPORT", 36, 44, 54},
    {193, "EKF_STATUS_REPORT", 71, 22, 26},
    {194, "PID_TUNING", 98, 25, 33},
    {195, "DEEPSTALL", 120, 37, 37},
    {200, "GIMBAL_REPORT", 134, 42, 42},
    {201, "GIMBAL_CONTROL", 205, 14, 14},
    {214, "GIMBAL_TORQUE_CMD_REPORT", 69, 8, 8},
    {215, "GOPRO_HEARTBEAT", 101, 3, 3},
    {216, "GOPRO_GET_REQUEST", 50, 3, 3},
    {217, "GOPRO_GET_RESPONSE", 202, 6, 6},
    {218, "GOPRO_SET_REQUEST", 17, 7, 7},
    {219, "GOPRO_SET_RESPONSE", 162, 2, 2},
    {225, "EFI_STATUS", 208, 65, 73},
    {226, "RPM", 207, 8, 8},
    {230, "ESTIMATOR_STATUS", 163, 42, 42},
    {231, "WIND_COV", 105, 40, 40},
    {232, "GPS_INPUT", 151, 63, 65},
    {233, "GPS_RTCM_DATA", 35, 182, 182},
    {234, "HIGH_LATENCY", 150, 40, 40},
    {235, "HIGH_LATENCY2", 179, 42, 42},
    {241, "VIBRATION", 90, 32, 32},
    {242, "HOME_POSITION", 104, 52, 60},
    {243, "SET_HOME_POSITION", 85, 53, 61},
    {244, "MESSAGE_INTERVAL", 95, 6, 6},
    {245, "EXTENDED_SYS_STATE", 130, 2, 2},
    {246, "ADSB_VEHICLE", 184, 38, 38},
    {247, "COLLISION", 81, 19, 19},
    {248, "V2_EXTENSION", 8, 254, 254},
    {249, "MEMORY_VECT", 204, 36, 36},
    {250, "DEBUG_VECT", 49, 30, 30},
    {251, "NAMED_VALUE_FLOAT", 170, 18, 18},
    {252, "NAMED_VALUE_INT", 44, 18, 18},
    {253, "STATUSTEXT", 83, 51, 54},
    {254, "DEBUG", 46, 9, 9},
    {256, "SETUP_SIGNING", 71, 42, 42},
    {257, "BUTTON_CHANGE", 131, 9, 9},
    {258, "PLAY_TUNE", 187, 32, 232},
    {259, "CAMERA_INFORMATION", 92, 235, 237},
    {260, "CAMERA_SETTINGS", 146, 5, 14},
    {261, "STORAGE_INFORMATION", 179, 27, 61},
    {262, "CAMERA_CAPTURE_STATUS", 12, 18, 23},
    {263, "CAMERA_IMAGE_CAPTURED", 133, 255, 255},
    {264, "FLIGHT_INFORMATION", 49, 28, 32},
    {265, "MOUNT_ORIENTATION", 26, 16, 20},
    {266, "LOGGING_DATA", 193, 255, 255},
    {267, "LOGGING_DATA_ACKED", 35, 255, 255},
    {268, "LOGGING_ACK", 14, 4, 4},
    {269, "VIDEO_STREAM_INFORMATION", 109, 213, 215},
    {270, "VIDEO_STREAM_STATUS", 59, 19, 20},
    {271, "CAMERA_FOV_STATUS", 22, 52, 53},
    {275, "CAMERA_TRACKING_IMAGE_STATUS", 126, 31, 32},
    {276, "CAMERA_TRACKING_GEO_STATUS", 18, 49, 50},
    {277, "CAMERA_THERMAL_RANGE", 62, 30, 30},
    {280, "GIMBAL_MANAGER_INFORMATION", 70, 33, 33},
    {281, "GIMBAL_MANAGER_STATUS", 48, 13, 13},
    {282, "GIMBAL_MANAGER_SET_ATTITUDE", 123, 35, 35},
    {283, "GIMBAL_DEVICE_INFORMATION", 74, 144, 145},
    {284, "GIMBAL_DEVICE_SET_ATTITUDE", 99, 32, 32},
    {285, "GIMBAL_DEVICE_ATTITUDE_STATUS", 137, 40, 49},
    {286, "AUTOPILOT_STATE_FOR_GIMBAL_DEVICE", 210, 53, 57},
    {287, "GIMBAL_MANAGER_SET_PITCHYAW", 1, 23, 23},
    {288, "GIMBAL_MANAGER_SET_MANUAL_CONTROL", 20, 23, 23},
    {295, "AIRSPEED", 234, 12, 12},
    {299, "WIFI_CONFIG_AP", 19, 96, 98},
    {301, "AIS_VESSEL", 243, 58, 58},
    {310, "UAVCAN_NODE_STATUS", 28, 17, 17},
    {311, "UAVCAN_NODE_INFO", 95, 116, 116},
    {320, "PARAM_EXT_REQUEST_READ", 243, 20, 20},
    {321, "PARAM_EXT_REQUEST_LIST", 88, 2, 2},
    {322, "PARAM_EXT_VALUE", 243, 149, 149},
    {323, "PARAM_EXT_SET", 78, 147, 147},
    {324, "PARAM_EXT_ACK", 132, 146, 146},
    {330, "OBSTACLE_DISTANCE", 23, 158, 167},
    {331, "ODOMETRY", 91, 230, 233},
    {332, "TRAJECTORY_REPRESENTATION_WAYPOINTS", 236, 239, 239},
    {333, "TRAJECTORY_REPRESENTATION_BEZIER", 231, 109, 109},
    {334, "CELLULAR_STATUS", 72, 10, 10},
    {335, "ISBD_LINK_STATUS", 225, 24, 24},
    {336, "CELLULAR_CONFIG", 245, 84, 84},
    {339, "RAW_RPM", 199, 5, 5},
    {340, "UTM_GLOBAL_POSITION", 99, 70, 70},
    {350, "DEBUG_FLOAT_ARRAY", 232, 20, 252},
    {360, "ORBIT_EXECUTION_STATUS", 11, 25, 25},
    {370, "SMART_BATTERY_INFO", 75, 87, 109},
    {371, "FUEL_STATUS", 10, 26, 26},
    {373, "GENERATOR_STATUS", 117, 42, 42},
    {375, "ACTUATOR_OUTPUT_STATUS", 251, 140, 140},
    {385, "TUNNEL", 147, 133, 133},
    {386, "CAN_FRAME", 132, 16, 16},
    {387, "CANFD_FRAME", 4, 72, 72},
    {388, "CAN_FILTER_MODIFY", 8, 37, 37},
    {395, "COMPONENT_INFORMATION", 0, 212, 212},
    {396, "COMPONENT_INFORMATION_BASIC", 50, 160, 160},
    {400, "PLAY_TUNE_V2", 110, 254, 254},
    {401, "SUPPORTED_TUNES", 183, 6, 6},
    {435, "AVAILABLE_MODES", 134, 46, 46},
    {436, "CURRENT_MODE", 193, 9, 9},
    {437, "AVAILABLE_MODES_MONITOR", 30, 1, 1},
    {440, "ILLUMINATOR_STATUS", 66, 35, 35},
    {9000, "WHEEL_DISTANCE", 113, 137, 137},
    {9005, "WINCH_STATUS", 117, 34, 34},
    {10001, "UAVIONIX_ADSB_OUT_CFG", 209, 20, 20},
    {10002, "UAVIONIX_ADSB_OUT_DYNAMIC", 186, 41, 41},
    {10003, "UAVIONIX_ADSB_TRANSCEIVER_HEALTH_REPORT", 4, 1, 1},
    {10004, "UAVIONIX_ADSB_OUT_CFG_REGISTRATION", 133, 9, 9},
    {10005, "UAVIONIX_ADSB_OUT_CFG_FLIGHTID", 103, 9, 9},
    {10006, "UAVIONIX_ADSB_GET", 193, 4, 4},
    {10007, "UAVIONIX_ADSB_OUT_CONTROL", 71, 17, 17},
    {10008, "UAVIONIX_ADSB_OUT_STATUS", 240, 14, 14},
    {11000, "DEVICE_OP_READ", 134, 51, 52},
    {11001, "DEVICE_OP_READ_REPLY", 15, 135, 136},
    {11002, "DEVICE_OP_WRITE", 234, 179, 180},
    {11003, "DEVICE_OP_WRITE_REPLY", 64, 5, 5},
    {11004, "SECURE_COMMAND", 11, 232, 232},
    {11005, "SECURE_COMMAND_REPLY", 93, 230, 230},
    {11010, "ADAP_TUNING", 46, 49, 49},
    {11011, "VISION_POSITION_DELTA", 106, 44, 44},
    {11020, "AOA_SSA", 205, 16, 16},
    {11030, "ESC_TELEMETRY_1_TO_4", 144, 44, 44},
    {11031, "ESC_TELEMETRY_5_TO_8", 133, 44, 44},
    {11032, "ESC_TELEMETRY_9_TO_12", 85, 44, 44},
    {11033, "OSD_PARAM_CONFIG", 195, 37, 37},
    {11034, "OSD_PARAM_CONFIG_REPLY", 79, 5, 5},
    {11035, "OSD_PARAM_SHOW_CONFIG", 128, 8, 8},
    {11036, "OSD_PARAM_SHOW_CONFIG_REPLY", 177, 34, 34},
    {11037, "OBSTACLE_DISTANCE_3D", 130, 28, 28},
    {11038, "WATER_DEPTH", 47, 38, 38},
    {11039, "MCU_STATUS", 142, 9, 9},
    {11040, "ESC_TELEMETRY_13_TO_16", 132, 44, 44},
    {11041, "ESC_TELEMETRY_17_TO_20", 208, 44, 44},
    {11042, "ESC_TELEMETRY_21_TO_24", 201, 44, 44},
    {11043, "ESC_TELEMETRY_25_TO_28", 193, 44, 44},
    {11044, "ESC_TELEMETRY_29_TO_32", 189, 44, 44},
    {12900, "OPEN_DRONE_ID_BASIC_ID", 114, 44, 44},
    {12901, "OPEN_DRONE_ID_LOCATION", 254, 59, 59},
    {12902, "OPEN_DRONE_ID_AUTHENTICATION", 140, 53, 53},
    {12903, "OPEN_DRONE_ID_SELF_ID", 249, 46, 46},
    {12904, "OPEN_DRONE_ID_SYSTEM", 77, 54, 54},
    {12905, "OPEN_DRONE_ID_OPERATOR_ID", 49, 43, 43},
    {12915, "OPEN_DRONE_ID_MESSAGE_PACK", 94, 249, 249},
    {12918, "OPEN_DRONE_ID_ARM_STATUS", 139, 51, 51},
    {12919, "OPEN_DRONE_ID_SYSTEM_UPDATE", 7, 18, 18},
    {12920, "HYGROMETER_SENSOR", 20, 5, 5},
    {42000, "ICAROUS_HEARTBEAT", 227, 1, 1},
    {42001, "ICAROUS_KINEMATIC_BANDS", 239, 46, 46},
};

// Published in the generated MAVLink C headers (c_library_v2, ardupilotmega.h, MAVLINK_MESSAGE_CRCS) for
// dialect messages that node-mavlink 2.3.0 predates.
constexpr Published kCLibrary[] = {
    {8, "LINK_NODE_STATUS", 117, 36, 36},      {80, "COMMAND_CANCEL", 14, 4, 4},
    {290, "ESC_INFO", 251, 46, 46},            {291, "ESC_STATUS", 10, 57, 57},
    {300, "PROTOCOL_VERSION", 217, 22, 22},    {380, "TIME_ESTIMATE_TO_TARGET", 232, 20, 20},
    {390, "ONBOARD_COMPUTER_STATUS", 156, 238, 238}, {410, "EVENT", 160, 53, 53},
    {411, "CURRENT_EVENT_SEQUENCE", 106, 3, 3}, {412, "REQUEST_EVENT", 33, 6, 6},
    {413, "RESPONSE_EVENT_ERROR", 77, 7, 7},
};
// clang-format on

const Published* published(std::uint32_t id) {
    for (const auto& table :
         {std::span<const Published>(kNodeMavlink), std::span<const Published>(kCLibrary)}) {
        const auto it =
            std::find_if(table.begin(), table.end(), [&](const Published& p) { return p.id == id; });
        if (it != table.end()) {
            return &*it;
        }
    }
    return nullptr;
}

// Messages that gained extension fields after the reference was published: only their full length differs.
constexpr std::string_view kExtendedSincePublished[] = {"CELLULAR_STATUS", "ONBOARD_COMPUTER_STATUS",
                                                        "GIMBAL_DEVICE_INFORMATION", "AVAILABLE_MODES"};

// Newer than both references (or, for 296, redefined since): their values come from the table alone.
constexpr std::string_view kUnpublished[] = {"GLOBAL_POSITION_SENSOR",
                                             "PARAM_ERROR",
                                             "FIGURE_EIGHT_EXECUTION_STATUS",
                                             "BATTERY_INFO",
                                             "RELAY_STATUS",
                                             "COMPONENT_METADATA",
                                             "LOWEHEISER_GOV_EFI",
                                             "NAMED_VALUE_STRING",
                                             "CUBEPILOT_RAW_RC",
                                             "HERELINK_VIDEO_STREAM_INFORMATION",
                                             "HERELINK_TELEM",
                                             "CUBEPILOT_FIRMWARE_UPDATE_START",
                                             "CUBEPILOT_FIRMWARE_UPDATE_RESP",
                                             "AIRLINK_AUTH",
                                             "AIRLINK_AUTH_RESPONSE"};

bool listed(std::span<const std::string_view> names, std::string_view name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

TEST(MavlinkDialect, CrcExtraAndLengthsMatchThePublishedValues) {
    std::size_t checked = 0;
    for (const MessageInfo& m : dialect_messages()) {
        const Published* p = published(m.id);
        if (p == nullptr) {
            EXPECT_TRUE(listed(kUnpublished, m.name))
                << m.name << " (" << m.id << ") has no published values";
            continue;
        }
        EXPECT_FALSE(listed(kUnpublished, m.name)) << m.name;
        ++checked;
        EXPECT_EQ(m.name, p->name) << m.id;
        EXPECT_EQ(int{m.crc_extra}, int{p->crc_extra}) << m.name;
        EXPECT_EQ(int{m.base_length}, int{p->min_length}) << m.name;
        if (listed(kExtendedSincePublished, m.name)) {
            EXPECT_GT(int{m.length}, int{p->max_length}) << m.name;
        } else {
            EXPECT_EQ(int{m.length}, int{p->max_length}) << m.name;
        }
    }
    EXPECT_EQ(checked + std::size(kUnpublished), dialect_messages().size());
}

TEST(MavlinkDialect, IsOrderedByIdAndFindsByIdAndName) {
    const auto all = dialect_messages();
    ASSERT_GT(all.size(), 300u);
    for (std::size_t i = 1; i < all.size(); ++i) {
        EXPECT_LT(all[i - 1].id, all[i].id);
    }
    for (const MessageInfo& m : all) {
        EXPECT_EQ(find_dialect_message(m.id), &m);
        EXPECT_EQ(find_dialect_message(m.name), &m);
        ASSERT_EQ(m.declaration_order.size(), m.fields.size()) << m.name;
        std::size_t end = 0;
        for (const FieldInfo& f : m.fields) {
            EXPECT_EQ(f.offset, end) << m.name << "." << f.name;
            end += f.size();
        }
        EXPECT_EQ(end, m.length) << m.name;
    }
    EXPECT_EQ(find_dialect_message(std::uint32_t{9999}), nullptr);
    EXPECT_EQ(find_dialect_message("NO_SUCH_MESSAGE"), nullptr);
}

TEST(MavlinkDialect, EveryTypedMessageIsInTheDialectWithTheSameLayout) {
    for (const MessageInfo& typed : all_messages()) {
        const MessageInfo* d = find_dialect_message(typed.id);
        ASSERT_NE(d, nullptr) << typed.name << " (" << typed.id << ") is not in dialect.def";
        EXPECT_TRUE(d->typed) << typed.name;
        EXPECT_EQ(d->name, typed.name);
        EXPECT_EQ(int{d->crc_extra}, int{typed.crc_extra}) << typed.name;
        EXPECT_EQ(int{d->base_length}, int{typed.base_length}) << typed.name;
        EXPECT_EQ(int{d->length}, int{typed.length}) << typed.name;
        ASSERT_EQ(d->fields.size(), typed.fields.size()) << typed.name;
        for (std::size_t i = 0; i < typed.fields.size(); ++i) {
            const FieldInfo& a = typed.fields[i];
            const FieldInfo& b = d->fields[i];
            EXPECT_TRUE(a.name == b.name && a.type == b.type && a.array_length == b.array_length &&
                        a.offset == b.offset && a.extension == b.extension)
                << typed.name << " wire field " << i << ": " << a.name << " / " << b.name;
            EXPECT_EQ(typed.declaration_order[i], d->declaration_order[i]) << typed.name;
        }
    }
    const auto typed_in_dialect = std::count_if(dialect_messages().begin(), dialect_messages().end(),
                                                [](const MessageInfo& m) { return m.typed; });
    EXPECT_EQ(static_cast<std::size_t>(typed_in_dialect), all_messages().size());
}

std::vector<Frame> parse(std::span<const std::uint8_t> bytes) {
    std::vector<Frame> frames;
    Parser parser;
    auto on_frame = [&](const Frame& f) { frames.push_back(f); };
    parser.push(bytes, on_frame);
    parser.finish(on_frame);
    return frames;
}

std::vector<std::uint8_t> frame_of(const MessageInfo& info, std::uint8_t fill) {
    std::array<std::uint8_t, kMaxPayload> payload{};
    std::fill_n(payload.begin(), info.length, fill);
    std::array<std::uint8_t, kMaxFrameLength> out{};
    const std::size_t n = encode_message(FrameHeader{Version::V2, 7, 1, 1, info.id, 0}, info,
                                         std::span(payload).first(info.length), out);
    return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

TEST(MavlinkDialect, ParserVerifiesEveryDialectMessageAndMarksTheTypedOnes) {
    for (const MessageInfo& m : dialect_messages()) {
        const auto frames = parse(frame_of(m, 0x5A));
        ASSERT_EQ(frames.size(), 1u) << m.name;
        EXPECT_TRUE(frames[0].checksum_verified) << m.name;
        EXPECT_EQ(frames[0].typed, m.typed) << m.name;
        EXPECT_EQ(reencode(frames[0]), frame_of(m, 0x5A)) << m.name;
    }
    // A damaged checksum is caught for an untyped dialect message too.
    const MessageInfo* ahrs = find_dialect_message("AHRS");
    ASSERT_NE(ahrs, nullptr);
    ASSERT_FALSE(ahrs->typed);
    auto bytes = frame_of(*ahrs, 0x11);
    bytes[12] ^= 0x01;
    Parser parser;
    std::size_t delivered = 0;
    parser.push(bytes, [&](const Frame&) { ++delivered; });
    parser.finish([&](const Frame&) { ++delivered; });
    EXPECT_EQ(delivered, 0u);
    EXPECT_EQ(parser.stats().bad_checksum + parser.stats().truncated, 1u);
}

TEST(MavlinkDialect, AnIdOutsideTheDialectStaysUnverified) {
    ASSERT_EQ(find_dialect_message(std::uint32_t{9999}), nullptr);
    std::array<std::uint8_t, kMaxFrameLength> out{};
    const std::array<std::uint8_t, 3> payload{1, 2, 3};
    const std::size_t n = encode_frame(FrameHeader{Version::V2, 1, 1, 1, 9999, 0}, 42, payload, out);
    const auto frames = parse(std::span(out).first(n));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_FALSE(frames[0].checksum_verified);
    EXPECT_FALSE(frames[0].typed);
    EXPECT_TRUE(reencode(frames[0]).empty());
}

}  // namespace
}  // namespace dialect_test
}  // namespace airseg::mavlink
