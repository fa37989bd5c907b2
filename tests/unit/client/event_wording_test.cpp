// The words of the vehicle's events on the ground (groundside/event_wording.hpp), shared by the map, watch
// and log: plan terms, each happening once, slot numbers only in a debug view.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "groundside/event_wording.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::groundside {
namespace {

namespace proto = groundlink::protocol;
using Sev = proto::Event::Severity;

proto::Event info(std::string text) {
    return {Sev::Info, std::move(text)};
}

TEST(EventWording, PlanEventsAreSaidInThePlansNumbering) {
    // The vehicle's "plan waypoint 7 reached" is index 7: the plan's eighth waypoint.
    EXPECT_EQ(word_event(info("plan waypoint 7 reached"), 1, 12).text, "waypoint 8 of 12 reached");
    EXPECT_EQ(word_event(info("plan waypoint 7 reached"), 1, std::nullopt).text, "waypoint 8 reached");
    EXPECT_EQ(word_event(info("plan waypoint 0 reached"), 3, 1).text, "waypoint 1 of 1 reached")
        << "the last one arrives with the plan already done";
    EXPECT_EQ(word_event(info("plan waypoints reached: 3 more, next 12"), 1, 20).text,
              "3 waypoints reached, heading for waypoint 13 of 20");
    EXPECT_FALSE(word_event(info("plan waypoint 7 reached"), 1, 12).debug);
    EXPECT_EQ(word_event(info("plan waypoint 7 reached"), 1, 12).raw, "plan waypoint 7 reached");
    // Not quite the vehicle's form: left as it is.
    EXPECT_EQ(word_event(info("plan waypoint x reached"), 1, 12).text, "plan waypoint x reached");
    EXPECT_EQ(word_event(info("plan waypoint 7 reached twice"), 1, 12).text, "plan waypoint 7 reached twice");
    EXPECT_EQ(waypoint_words(12, 12), "waypoint 13") << "an index past the count is not 'of N'";
}

TEST(EventWording, TheWindowsSlotsAreDebugLinesWhileAPlanDrives) {
    for (const std::uint8_t driving : {std::uint8_t{1}, std::uint8_t{2}}) {
        for (const char* text : {"mission slot 3 reached", "autopilot: Reached waypoint #3 dist 1m",
                                 "autopilot: Flight plan received", "autopilot: flight plan received",
                                 "autopilot: Mission: 4 WP"}) {
            const auto w = word_event(info(text), driving, 12);
            EXPECT_TRUE(w.debug) << text;
            EXPECT_EQ(w.raw, text) << "the debug view keeps the slot number";
        }
    }
    // Without a plan, a ground station's mission: its slots are its waypoints.
    EXPECT_FALSE(word_event(info("mission slot 3 reached"), 0, std::nullopt).debug);
    EXPECT_FALSE(word_event(info("autopilot: Reached waypoint #3 dist 1m"), 3, 12).debug);
    // Other texts of the board stay, whatever the plan does.
    EXPECT_FALSE(word_event(info("autopilot: Mission complete, changing mode to HOLD"), 1, 12).debug);
    EXPECT_FALSE(word_event({Sev::Error, "autopilot: PreArm: Compass not calibrated"}, 1, 12).debug);
}

TEST(EventWording, AModeChangeThatChangesNothingIsADebugLine) {
    EXPECT_TRUE(word_event(info("autopilot mode MANUAL -> MANUAL"), 0, std::nullopt).debug);
    EXPECT_TRUE(
        word_event(info("autopilot mode HOLD -> HOLD, not asked for by airsegd (RC, failsafe)"), 1, 3).debug);
    EXPECT_FALSE(word_event(info("autopilot mode MANUAL -> HOLD"), 0, std::nullopt).debug);
    EXPECT_FALSE(word_event(info("autopilot mode AUTO -> AUTOTUNE"), 0, std::nullopt).debug);
    // The vehicle's state changed: something happened, though the autopilot's mode stayed.
    EXPECT_FALSE(
        word_event(info("vehicle STARTING -> DIRECTED (autopilot mode MANUAL -> MANUAL)"), 0, std::nullopt)
            .debug);
}

/// Counts the lines an operator reads (no debug line) of a stream of events.
struct Seen {
    std::vector<std::string> shown;
    std::vector<std::string> debug;
};

TEST(EventWording, EachWaypointIsOneLineWhateverTheVehicleSends) {
    EventWording w;
    w.set_plan_state(1);
    w.set_waypoints(12);
    Seen seen;
    auto t = EventWording::Clock::now();
    // An older vehicle's three lines per waypoint plus the plan's own event, and each plan event delivered
    // twice (a second path to the same vehicle): 12 waypoints, 8 events each.
    for (int i = 0; i < 12; ++i) {
        const int slot = 2 + i % 6;  // the window's slots cycle 2..7
        for (const std::string& text :
             {fmt::format("autopilot: Reached waypoint #{} dist 1m", slot),
              fmt::format("mission slot {} reached", slot), std::string("autopilot: Flight plan received"),
              fmt::format("plan waypoint {} reached", i), fmt::format("plan waypoint {} reached", i),
              std::string("autopilot mode AUTO -> AUTO")}) {
            const auto e = w.word(info(text), t);
            (e.debug ? seen.debug : seen.shown).push_back(e.text);
        }
        t += std::chrono::seconds(3);
    }
    ASSERT_EQ(seen.shown.size(), 12u) << "one line per waypoint";
    EXPECT_EQ(seen.shown.front(), "waypoint 1 of 12 reached");
    EXPECT_EQ(seen.shown[3], "waypoint 4 of 12 reached");
    EXPECT_EQ(seen.shown.back(), "waypoint 12 of 12 reached");
    EXPECT_EQ(seen.debug.size(), 12u * 5);
    for (const auto& line : seen.shown) {
        EXPECT_EQ(line.find("slot"), std::string::npos) << line;
        EXPECT_EQ(line.find('#'), std::string::npos) << line;
    }
}

TEST(EventWording, TheSameWordsAgainSoonAreOneHappeningLaterTheyAreAnother) {
    EventWording w;
    const auto t = EventWording::Clock::now();
    EXPECT_FALSE(w.word(info("autopilot: Throttle armed"), t).debug);
    EXPECT_TRUE(w.word(info("autopilot: Throttle armed"), t + std::chrono::seconds(1)).debug);
    EXPECT_FALSE(w.word(info("autopilot: Throttle disarmed"), t + std::chrono::seconds(2)).debug);
    EXPECT_FALSE(w.word(info("autopilot: Throttle armed"), t + std::chrono::seconds(3)).debug)
        << "something else in between: a new happening";
    EXPECT_FALSE(w.word(info("autopilot: Throttle armed"), t + std::chrono::seconds(30)).debug);

    // A waypoint already said reached is not said again; a new plan numbers from the start again.
    w.set_plan_state(1);
    EXPECT_FALSE(w.word(info("plan waypoint 0 reached"), t).debug);
    EXPECT_TRUE(w.word(info("plan waypoint 0 reached"), t + std::chrono::seconds(60)).debug);
    w.set_plan_state(2);  // paused: the same plan
    EXPECT_TRUE(w.word(info("plan waypoint 0 reached"), t + std::chrono::seconds(61)).debug);
    w.set_plan_state(3);
    w.set_plan_state(1);
    EXPECT_FALSE(w.word(info("plan waypoint 0 reached"), t + std::chrono::seconds(62)).debug);
}

TEST(WatchState, ListsOneLinePerWaypointAndTheSlotsOnlyInItsDebugView) {
    for (const bool debug : {false, true}) {
        WatchState w;
        w.set_debug(debug);
        const auto t0 = WatchState::Clock::now();
        proto::Telemetry t;
        t.plan_state = 1;
        t.next_waypoint = 3;
        w.take(t, t0);
        for (const char* text :
             {"autopilot: Reached waypoint #5 dist 1m", "mission slot 5 reached",
              "autopilot: Flight plan received", "plan waypoint 3 reached", "autopilot mode AUTO -> AUTO"}) {
            w.take(info(text), t0);
        }
        const auto events = w.to_json(t0)["events"];
        const auto screen = w.render(t0);
        EXPECT_NE(screen.find("next waypoint 4 (index 3)"), std::string::npos) << screen;
        if (!debug) {
            ASSERT_EQ(events.size(), 1u) << events.dump();
            EXPECT_EQ(events[0], "info: waypoint 4 reached");
            EXPECT_EQ(screen.find("slot"), std::string::npos) << screen;
        } else {
            ASSERT_EQ(events.size(), 5u) << events.dump();
            EXPECT_EQ(events[1], "info: (debug) mission slot 5 reached");
            EXPECT_EQ(events[3], "info: waypoint 4 reached [plan waypoint 3 reached]");
            EXPECT_EQ(events[4], "info: (debug) autopilot mode AUTO -> AUTO");
        }
    }
}

}  // namespace
}  // namespace airseg::groundside
