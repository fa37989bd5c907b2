/* The yardstick of bench/mavlink/callgrind.sh: the official MAVLink C library (c_library_v2, not part of
 * this tree) receiving the same telemetry stream, mavlink_parse_char() byte by byte and, in parse-decode
 * mode, the generated mavlink_msg_*_decode() of every message.
 *
 *   clib_parse STREAM_FILE parse|parse-decode READ_SIZE
 *   clib_parse STREAM_FILE decode
 *
 * Built by the script against the library's headers (-I C_LIBRARY_DIR, and clib_messages.h, which includes
 * each message's header from the folder it is in) with the CRC table airseg's bench
 * writes (-include crcs.h: MAVLINK_MESSAGE_CRCS of the messages airseg knows), so that the whole dialect is
 * not needed. Only the measured loop is collected, as in callgrind_parse.cpp. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <valgrind/callgrind.h>

#ifndef MAVLINK_STX
#define MAVLINK_STX 253
#endif
#define MAVLINK_ENDIAN MAVLINK_LITTLE_ENDIAN
#define MAVLINK_ALIGNED_FIELDS 1
#define MAVLINK_CRC_EXTRA 1
#define MAVLINK_COMMAND_24BIT 1

#include "mavlink_types.h"
#include "protocol.h"

/* The message headers of the 14 messages, wherever the library's layout puts them: today's c_library_v2 has
 * HEARTBEAT in minimal/, GLOBAL_POSITION_INT in standard/ and the rest in common/, older checkouts all of them
 * in common/. bench/mavlink/callgrind.sh finds each and writes this header. */
#include "clib_messages.h"

#define KEEP(value) __asm__ volatile("" : : "g"(&(value)) : "memory")
#define DECODE(name, field)                  \
    {                                        \
        mavlink_##name##_t m;                \
        mavlink_msg_##name##_decode(msg, &m); \
        KEEP(m);                             \
        return (double)m.field;              \
    }

/* The same messages and fields as decode_frame() in callgrind_parse.cpp. */
static double decode_message(const mavlink_message_t* msg) {
    switch (msg->msgid) {
        case MAVLINK_MSG_ID_HEARTBEAT:
            DECODE(heartbeat, custom_mode)
        case MAVLINK_MSG_ID_SYS_STATUS:
            DECODE(sys_status, voltage_battery)
        case MAVLINK_MSG_ID_SYSTEM_TIME:
            DECODE(system_time, time_boot_ms)
        case MAVLINK_MSG_ID_GPS_RAW_INT:
            DECODE(gps_raw_int, satellites_visible)
        case MAVLINK_MSG_ID_ATTITUDE:
            DECODE(attitude, yaw)
        case MAVLINK_MSG_ID_GLOBAL_POSITION_INT:
            DECODE(global_position_int, lat)
        case MAVLINK_MSG_ID_SERVO_OUTPUT_RAW:
            DECODE(servo_output_raw, servo1_raw)
        case MAVLINK_MSG_ID_MISSION_CURRENT:
            DECODE(mission_current, seq)
        case MAVLINK_MSG_ID_NAV_CONTROLLER_OUTPUT:
            DECODE(nav_controller_output, wp_dist)
        case MAVLINK_MSG_ID_RC_CHANNELS:
            DECODE(rc_channels, chan3_raw)
        case MAVLINK_MSG_ID_VFR_HUD:
            DECODE(vfr_hud, groundspeed)
        case MAVLINK_MSG_ID_RADIO_STATUS:
            DECODE(radio_status, rssi)
        case MAVLINK_MSG_ID_BATTERY_STATUS:
            DECODE(battery_status, current_consumed)
        case MAVLINK_MSG_ID_STATUSTEXT:
            DECODE(statustext, severity)
        default:
            return 0;
    }
}

static unsigned char* read_stream(const char* path, size_t* size) {
    FILE* f = fopen(path, "rb");
    if (f == NULL) {
        perror(path);
        exit(1);
    }
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char* bytes = malloc(*size);
    if (bytes == NULL || fread(bytes, 1, *size, f) != *size) {
        exit(1);
    }
    fclose(f);
    return bytes;
}

static mavlink_message_t messages[20000];

__attribute__((noinline)) static size_t run_parse(const unsigned char* bytes, size_t size, size_t read_size,
                                                  int with_decode, double* sink) {
    mavlink_message_t msg;
    mavlink_status_t status;
    size_t frames = 0;
    CALLGRIND_TOGGLE_COLLECT;
    for (size_t i = 0; i < size; i += read_size) {
        const size_t end = i + read_size < size ? i + read_size : size;
        for (size_t k = i; k < end; ++k) {
            if (mavlink_parse_char(MAVLINK_COMM_0, bytes[k], &msg, &status)) {
                ++frames;
                if (with_decode) {
                    *sink += decode_message(&msg);
                }
            }
        }
    }
    CALLGRIND_TOGGLE_COLLECT;
    return frames;
}

__attribute__((noinline)) static size_t run_decode(const unsigned char* bytes, size_t size, double* sink) {
    mavlink_message_t msg;
    mavlink_status_t status;
    size_t count = 0;
    for (size_t k = 0; k < size; ++k) {
        if (mavlink_parse_char(MAVLINK_COMM_1, bytes[k], &msg, &status) &&
            count < sizeof messages / sizeof messages[0]) {
            messages[count++] = msg;
        }
    }
    CALLGRIND_TOGGLE_COLLECT;
    for (size_t i = 0; i < count; ++i) {
        *sink += decode_message(&messages[i]);
    }
    CALLGRIND_TOGGLE_COLLECT;
    return count;
}

int main(int argc, char** argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: clib_parse STREAM_FILE parse|parse-decode READ_SIZE | decode\n");
        return 2;
    }
    size_t size = 0;
    unsigned char* bytes = read_stream(argv[1], &size);
    double sink = 0;
    if (strcmp(argv[2], "decode") == 0) {
        const size_t n = run_decode(bytes, size, &sink);
        printf("messages %zu sink %g\n", n, sink);
        return 0;
    }
    if (argc != 4 || atoi(argv[3]) <= 0) {
        return 2;
    }
    const size_t frames =
        run_parse(bytes, size, (size_t)atoi(argv[3]), strcmp(argv[2], "parse-decode") == 0, &sink);
    printf("bytes %zu frames %zu sink %g\n", size, frames, sink);
    free(bytes);
    return 0;
}
