#pragma once
// A ground station talking to an in-process RoverSim in simulated time: frames go in through the sim's
// byte interface and come back through the project's parser, and time jumps from deadline to deadline.
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim::test {

namespace mv = mavlink;

inline constexpr TimePoint kStart = TimePoint{} + std::chrono::hours(1);

struct Received {
    TimePoint at;
    mv::Frame frame;
};

class SimHarness {
  public:
    explicit SimHarness(RoverSimConfig config = {}, std::uint8_t sysid = 255, std::uint8_t compid = 190)
        : sim(std::move(config), kStart), gcs(sysid, compid) {}

    template <mv::Message M>
    void send(M m, mv::Encoder* from = nullptr) {
        if constexpr (requires { m.target_system; }) {
            if (m.target_system == 0) {
                m.target_system = 1;
            }
        }
        const auto bytes = (from != nullptr ? *from : gcs).encode(m);
        sim.handle_bytes(bytes, now);
        collect();
    }

    /// Runs simulated time forward by `d`, stopping at each deadline of the sim.
    void run_for(Duration d) { run_until_time(now + d); }
    void run_until_time(TimePoint end) {
        for (int guard = 0; guard < 10'000'000; ++guard) {
            const TimePoint next = sim.poll_timeout();
            if (next > end) {
                now = end;
                sim.handle_timeout(now);
                collect();
                return;
            }
            now = std::max(now, next);
            sim.handle_timeout(now);
            collect();
        }
        ADD_FAILURE() << "the simulator does not let time pass (livelock)";
    }
    /// Runs until `done` holds (checked after each deadline) or `limit` of simulated time passes.
    bool run_until(const std::function<bool()>& done, Duration limit) {
        const TimePoint end = now + limit;
        while (!done()) {
            if (now >= end) {
                return false;
            }
            const TimePoint next = std::min(sim.poll_timeout(), end);
            now = std::max(now, next);
            sim.handle_timeout(now);
            collect();
        }
        return true;
    }

    /// Frames of message M received since index `from`.
    template <mv::Message M>
    std::vector<M> all(std::size_t from = 0) const {
        std::vector<M> out;
        for (std::size_t i = from; i < received.size(); ++i) {
            if (auto m = mv::decode<M>(received[i].frame)) {
                out.push_back(*m);
            }
        }
        return out;
    }
    template <mv::Message M>
    std::optional<M> last(std::size_t from = 0) const {
        auto v = all<M>(from);
        if (v.empty()) {
            return std::nullopt;
        }
        return v.back();
    }
    /// Waits (in simulated time) for a message M matching `pred` after index `from`.
    template <mv::Message M>
    std::optional<M> wait_for(const std::function<bool(const M&)>& pred, Duration limit,
                              std::size_t from = SIZE_MAX) {
        std::size_t scan = from == SIZE_MAX ? received.size() : from;
        std::optional<M> found;
        run_until(
            [&] {
                for (; scan < received.size(); ++scan) {
                    if (auto m = mv::decode<M>(received[scan].frame); m && pred(*m)) {
                        found = m;
                        ++scan;
                        return true;
                    }
                }
                return false;
            },
            limit);
        return found;
    }
    template <mv::Message M>
    std::optional<M> wait_for(Duration limit, std::size_t from = SIZE_MAX) {
        return wait_for<M>([](const M&) { return true; }, limit, from);
    }
    bool wait_text(std::string_view needle, Duration limit) {
        return wait_for<mv::Statustext>(
                   [&](const mv::Statustext& t) {
                       return mv::text_of(t.text).find(needle) != std::string_view::npos;
                   },
                   limit)
            .has_value();
    }

    void boot() {
        ASSERT_TRUE(run_until([&] { return sim.state().phase == BootPhase::Ready; }, seconds(30)));
    }
    /// MAV_CMD_COMPONENT_ARM_DISARM as a ground station sends it; the COMMAND_ACK's result (nothing if none).
    std::optional<std::uint8_t> arm(bool on = true, float param2 = 0) {
        mv::CommandLong c;
        c.command = 400;
        c.param1 = on ? 1.0F : 0.0F;
        c.param2 = param2;
        const std::size_t from = received.size();
        send(c);
        const auto ack = last<mv::CommandAck>(from);
        return ack ? std::optional<std::uint8_t>(ack->result) : std::nullopt;
    }
    /// Boots and, on a board that waits to be armed (modern: ARMING_REQUIRE 1), arms it: ready to drive.
    void boot_armed() {
        boot();
        if (!sim.state().armed) {
            ASSERT_EQ(arm(), std::optional<std::uint8_t>(0));
        }
        ASSERT_TRUE(sim.state().armed);
    }

    /// Uploads `items` (home first) with the plain protocol; returns the final MISSION_ACK type.
    std::optional<std::uint8_t> upload(const std::vector<mv::MissionItemInt>& items) {
        mv::MissionCount c;
        c.count = static_cast<std::uint16_t>(items.size());
        const std::size_t from = received.size();
        send(c);
        std::size_t scan = from;
        for (int guard = 0; guard < 100000; ++guard) {
            std::optional<std::uint16_t> wanted;
            std::optional<std::uint8_t> acked;
            run_until(
                [&] {
                    for (; scan < received.size(); ++scan) {
                        const auto& f = received[scan].frame;
                        if (auto r = mv::decode<mv::MissionRequest>(f)) {
                            wanted = r->seq;
                        } else if (auto r2 = mv::decode<mv::MissionRequestInt>(f)) {
                            wanted = r2->seq;
                        } else if (auto a = mv::decode<mv::MissionAck>(f); a && a->type != 13) {
                            acked = a->type;  // INVALID_SEQUENCE answers a duplicate; the transfer goes on
                        }
                        if (wanted || acked) {
                            ++scan;
                            return true;
                        }
                    }
                    return false;
                },
                seconds(20));
            if (acked) {
                return acked;
            }
            if (!wanted) {
                return std::nullopt;
            }
            mv::MissionItemInt item = items.at(*wanted);
            item.seq = *wanted;
            send(item);
        }
        return std::nullopt;
    }

    /// Uploads float `items` (home first) with MISSION_COUNT / MISSION_ITEM, as a MAVLink 1 ground station
    /// does; returns the final MISSION_ACK type (a refusal of one item included), nothing on silence.
    std::optional<std::uint8_t> upload_float(const std::vector<mv::MissionItem>& items) {
        mv::MissionCount c;
        c.count = static_cast<std::uint16_t>(items.size());
        std::size_t scan = received.size();
        send(c);
        for (int guard = 0; guard < 100000; ++guard) {
            std::optional<std::uint16_t> wanted;
            std::optional<std::uint8_t> acked;
            run_until(
                [&] {
                    for (; scan < received.size(); ++scan) {
                        const auto& f = received[scan].frame;
                        if (auto r = mv::decode<mv::MissionRequest>(f)) {
                            wanted = r->seq;
                        } else if (auto a = mv::decode<mv::MissionAck>(f); a && a->type != 13) {
                            acked = a->type;
                        }
                        if (wanted || acked) {
                            ++scan;
                            return true;
                        }
                    }
                    return false;
                },
                seconds(20));
            if (acked) {
                return acked;
            }
            if (!wanted) {
                return std::nullopt;
            }
            mv::MissionItem item = items.at(*wanted);
            item.seq = *wanted;
            send(item);
        }
        return std::nullopt;
    }

    void set_mode(RoverMode mode) {
        mv::CommandLong c;
        c.command = 176;
        c.param1 = 1;
        c.param2 = static_cast<float>(mode);
        send(c);
    }
    /// The mode by SET_MODE (message 11), as 2.x ground stations did it.
    void set_mode_message(RoverMode mode) {
        mv::SetMode m;
        m.target_system = 1;
        m.base_mode = 1;  // MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        m.custom_mode = static_cast<std::uint32_t>(mode);
        send(m);
    }
    /// Texts received since index `from`.
    std::vector<std::string> texts(std::size_t from = 0) const {
        std::vector<std::string> out;
        for (const auto& t : all<mv::Statustext>(from)) {
            out.emplace_back(mv::text_of(t.text));
        }
        return out;
    }

    RoverSim sim;
    mv::Encoder gcs;
    TimePoint now = kStart;
    std::vector<Received> received;

  private:
    void collect() {
        const auto bytes = sim.poll_transmit();
        if (bytes.empty()) {
            return;  // the parser memcpy()s from data() even for an empty span, and data() may be null
        }
        parser_.push(bytes, [&](const mv::Frame& f) { received.push_back(Received{now, f}); });
    }
    mv::Parser parser_;
};

/// A waypoint `north` and `east` metres from `origin`.
inline mv::MissionItemInt waypoint(GeoPoint origin, double north, double east) {
    const GeoPoint p = offset(offset(origin, 0, north), 3.14159265358979323846 / 2, east);
    mv::MissionItemInt m;
    m.target_system = 1;
    m.target_component = 1;
    m.frame = 3;
    m.command = 16;
    m.autocontinue = 1;
    m.x = static_cast<std::int32_t>(std::lround(p.lat * 1e7));
    m.y = static_cast<std::int32_t>(std::lround(p.lon * 1e7));
    m.z = 0;
    return m;
}

/// The same item as MISSION_ITEM (degrees as float).
inline mv::MissionItem to_float(const mv::MissionItemInt& m) {
    mv::MissionItem f;
    f.target_system = m.target_system;
    f.target_component = m.target_component;
    f.seq = m.seq;
    f.frame = m.frame;
    f.command = m.command;
    f.current = m.current;
    f.autocontinue = m.autocontinue;
    f.param1 = m.param1;
    f.param2 = m.param2;
    f.param3 = m.param3;
    f.param4 = m.param4;
    f.x = static_cast<float>(m.x / 1e7);
    f.y = static_cast<float>(m.y / 1e7);
    f.z = m.z;
    return f;
}

inline std::vector<mv::MissionItem> to_float(const std::vector<mv::MissionItemInt>& items) {
    std::vector<mv::MissionItem> out;
    for (const auto& m : items) {
        out.push_back(to_float(m));
    }
    return out;
}

/// A mission item that is not a place (DO_ and CONDITION_ commands).
inline mv::MissionItem command_item(std::uint16_t command, float p1, float p2 = 0, float p3 = 0) {
    mv::MissionItem m;
    m.target_system = 1;
    m.target_component = 1;
    m.frame = 0;
    m.command = command;
    m.autocontinue = 1;
    m.param1 = p1;
    m.param2 = p2;
    m.param3 = p3;
    return m;
}

inline GeoPoint waypoint_point(const mv::MissionItemInt& m) {
    return GeoPoint{m.x / 1e7, m.y / 1e7};
}

/// Home plus `n` waypoints on a line northwards, `spacing` metres apart.
inline std::vector<mv::MissionItemInt> line_mission(GeoPoint home, int n, double spacing) {
    std::vector<mv::MissionItemInt> items{waypoint(home, 0, 0)};
    for (int i = 1; i <= n; ++i) {
        items.push_back(waypoint(home, spacing * i, 0));
    }
    return items;
}

}  // namespace airseg::apmsim::test
