#include "bench/mavlink/telemetry_stream.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink::bench {

TelemetryStream make_telemetry_stream(double seconds, unsigned seed) {
    TelemetryStream s;
    Encoder autopilot(1, 1);
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, 0.01f);
    std::array<std::uint8_t, kMaxFrameLength> frame{};
    auto emit = [&](const auto& msg) {
        const std::size_t n = autopilot.encode(msg, frame);
        s.bytes.insert(s.bytes.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(n));
        ++s.frames;
    };
    const int ticks = static_cast<int>(seconds * 10);  // 10 Hz base rate
    for (int tick = 0; tick < ticks; ++tick) {
        const auto ms = static_cast<std::uint32_t>(tick * 100);
        const double t = tick / 10.0;
        const double heading = std::fmod(t * 3.0, 360.0);
        const auto lat = static_cast<std::int32_t>(-353632621 + 40.0 * t * std::cos(heading * std::numbers::pi / 180));
        const auto lon = static_cast<std::int32_t>(1491652374 + 40.0 * t * std::sin(heading * std::numbers::pi / 180));

        Attitude att;
        att.time_boot_ms = ms;
        att.roll = noise(rng);
        att.pitch = noise(rng);
        att.yaw = static_cast<float>(heading * std::numbers::pi / 180);
        att.rollspeed = noise(rng);
        att.pitchspeed = noise(rng);
        att.yawspeed = 0.05f + noise(rng);
        emit(att);
        if (tick % 2 == 0) {
            GlobalPositionInt pos;
            pos.time_boot_ms = ms;
            pos.lat = lat;
            pos.lon = lon;
            pos.alt = 584000 + static_cast<std::int32_t>(rng() % 100);
            pos.relative_alt = static_cast<std::int32_t>(rng() % 100);
            pos.vx = static_cast<std::int16_t>(150 * std::cos(heading * std::numbers::pi / 180));
            pos.vy = static_cast<std::int16_t>(150 * std::sin(heading * std::numbers::pi / 180));
            pos.hdg = static_cast<std::uint16_t>(heading * 100);
            emit(pos);
            GpsRawInt gps;
            gps.time_usec = ms * 1000ULL;
            gps.fix_type = 3;
            gps.lat = lat;
            gps.lon = lon;
            gps.alt = pos.alt;
            gps.eph = 121;
            gps.epv = 200;
            gps.vel = 150;
            gps.cog = pos.hdg;
            gps.satellites_visible = 12;
            emit(gps);
            VfrHud hud;
            hud.groundspeed = 1.5f + noise(rng);
            hud.heading = static_cast<std::int16_t>(heading);
            hud.throttle = 35;
            hud.alt = 584.0f;
            emit(hud);
        }
        if (tick % 5 == 0) {
            SysStatus sys;
            sys.onboard_control_sensors_present = 0x1235C2F;
            sys.onboard_control_sensors_enabled = 0x1235C2F;
            sys.onboard_control_sensors_health = 0x1235C2F;
            sys.load = static_cast<std::uint16_t>(300 + rng() % 50);
            sys.voltage_battery = static_cast<std::uint16_t>(12600 - tick);
            sys.current_battery = 850;
            sys.battery_remaining = 87;
            emit(sys);
            NavControllerOutput nav;
            nav.nav_bearing = static_cast<std::int16_t>(heading);
            nav.target_bearing = static_cast<std::int16_t>(heading + 2);
            nav.wp_dist = static_cast<std::uint16_t>(120 - tick % 120);
            nav.xtrack_error = noise(rng);
            emit(nav);
            RcChannels rc;
            rc.time_boot_ms = ms;
            rc.chancount = 16;
            rc.chan1_raw = 1500;
            rc.chan2_raw = 1500;
            rc.chan3_raw = 1650;
            rc.chan4_raw = 1500;
            rc.chan5_raw = 1900;
            rc.rssi = 230;
            emit(rc);
            ServoOutputRaw servo;
            servo.time_usec = ms * 1000;
            servo.servo1_raw = 1520;
            servo.servo3_raw = 1640;
            emit(servo);
        }
        if (tick % 10 == 0) {
            Heartbeat hb;
            hb.type = 10;
            hb.autopilot = 3;
            hb.base_mode = 0x89;
            hb.custom_mode = 10;
            hb.system_status = 4;
            emit(hb);
            SystemTime st;
            st.time_unix_usec = 1700000000000000ULL + ms * 1000ULL;
            st.time_boot_ms = ms;
            emit(st);
            MissionCurrent mc;
            mc.seq = static_cast<std::uint16_t>(tick / 100);
            mc.total = 20;
            mc.mission_state = 3;
            emit(mc);
            BatteryStatus bat;
            bat.voltages = {4200, 4190, 4185, 65535, 65535, 65535, 65535, 65535, 65535, 65535};
            bat.current_battery = 850;
            bat.current_consumed = tick;
            bat.battery_remaining = 87;
            emit(bat);
            RadioStatus radio;
            radio.rssi = static_cast<std::uint8_t>(180 + rng() % 20);
            radio.remrssi = static_cast<std::uint8_t>(170 + rng() % 20);
            radio.txbuf = 95;
            radio.noise = 40;
            radio.remnoise = 42;
            emit(radio);
        }
        if (tick % 150 == 0) {
            Statustext text;
            text.severity = 6;
            set_text(text.text, "Mission: 3 WP");
            emit(text);
        }
    }
    return s;
}

}  // namespace airseg::mavlink::bench
