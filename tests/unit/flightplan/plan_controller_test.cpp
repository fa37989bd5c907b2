// PlanController in simulated time: what a plan asks of the autopilot, commands answered once or timed out,
// the link-loss reaction, an autopilot that reboots or reconnects mid-plan, pause and resume.
#include <gtest/gtest.h>

#include <algorithm>

#include <string>
#include <vector>

#include "services/flightplan/plan_controller.hpp"

namespace airseg::flightplan {
namespace {

using Status = CommandReply::Status;

constexpr const char* kPlan = R"(plan:
  name: ctl
  vehicle: {type: rover, cruise_speed: 1.5}
  home: {lat: 41.0, lon: 2.0}
  reactions:
    link_loss: {after: 20, action: ACTION}
  elements:
    - waypoint: {lat: 41.0001, lon: 2.0001}
    - waypoint: {lat: 41.0002, lon: 2.0001}
    - waypoint: {lat: 41.0003, lon: 2.0002}
)";

std::string plan_text(const std::string& action = "hold") {
    std::string text = kPlan;
    text.replace(text.find("ACTION"), 6, action);
    return text;
}

bool is_state_change(const autopilot::AutopilotRequest& r, autopilot::VehicleState to) {
    const auto* s = std::get_if<autopilot::RequestStateChange>(&r.op);
    return s && s->state == to;
}

bool is_upload(const autopilot::AutopilotRequest& r) {
    return std::holds_alternative<autopilot::UploadMission>(r.op);
}

PlanControllerConfig with_a_state_store() {
    PlanControllerConfig config;
    config.keeps_progress = true;
    return config;
}

// The controller, an autopilot that confirms what it is asked (or not, when told so) and the outputs seen.
struct Rig {
    explicit Rig(PlanControllerConfig config = {}) : c(std::move(config)) {
        c.start(now);
        drain();
    }

    void drain() {
        while (auto o = c.poll_output()) {
            if (auto* call = std::get_if<AutopilotCall>(&*o)) {
                requests.push_back(call->request);
                pending.push_back(*call);
            } else if (auto* t = std::get_if<ReactionTrigger>(&*o)) {
                triggers.push_back(*t);
            } else if (auto* e = std::get_if<FeederEvent>(&*o)) {
                events.push_back(*e);
            }
        }
        while (auto r = c.poll_reply()) {
            replies.push_back(*r);
        }
        while (auto s = c.poll_save()) {
            saves.push_back(*s);
            c.on_saved(*s, save_error);
        }
        while (c.poll_status()) {
        }
        while (c.poll_log()) {
        }
    }

    void ready(unsigned reconnects = 0, unsigned reboots = 0) {
        autopilot::AutopilotStatus s;
        s.ready = true;
        s.reconnects = reconnects;
        s.reboots = reboots;
        c.on_autopilot_status(s, now);
        drain();
    }

    void not_ready() {
        c.on_autopilot_status(autopilot::AutopilotStatus{}, now);
        drain();
    }

    /// Confirms every request, reporting the mode changes asked for, until nothing more is asked.
    void confirm_all() {
        for (int guard = 0; guard < 100 && !pending.empty(); ++guard) {
            const auto call = pending.front();
            const auto& r = call.request;
            pending.erase(pending.begin());
            now += milliseconds(50);
            c.on_request_done(call.id, autopilot::RequestDone{}, now);
            drain();
            if (const auto* s = std::get_if<autopilot::RequestStateChange>(&r.op)) {
                autopilot::ModeChanged m;
                m.to = s->state;
                m.cause = autopilot::ModeChangeCause::Requested;
                c.on_mode_changed(m, now);
                drain();
            }
        }
    }

    void advance(Duration d) {
        const TimePoint until = now + d;
        while (c.poll_timeout() <= until) {
            now = std::max(now, c.poll_timeout());
            c.handle_timeout(now);
            drain();
        }
        now = until;
    }

    CommandId load(const std::string& text, bool paused = false) {
        const CommandId id = next_id++;
        auto plan = c.prepare_load(id, LoadRequest{text, "test.yaml", false});
        if (plan) {
            c.load(id, std::move(*plan), false, paused, "test.yaml", now);
        }
        drain();
        return id;
    }

    std::vector<CommandReply> replies_to(CommandId id) const {
        std::vector<CommandReply> out;
        for (const auto& r : replies) {
            if (r.id == id) {
                out.push_back(r);
            }
        }
        return out;
    }

    std::size_t count(bool (*pred)(const autopilot::AutopilotRequest&)) const {
        std::size_t n = 0;
        for (const auto& r : requests) {
            n += pred(r) ? 1 : 0;
        }
        return n;
    }

    /// A ready autopilot driving a plan whose link-loss reaction is `action`, the link up or down at start.
    void run_plan(const std::string& action, bool link_up) {
        ready();
        c.on_link(link_up, now);
        load(plan_text(action));
        confirm_all();
    }

    std::string state() const { return c.progress_json()["state"].get<std::string>(); }

    PlanController c;
    TimePoint now{};
    CommandId next_id = 1;
    std::vector<autopilot::AutopilotRequest> requests;
    std::vector<AutopilotCall> pending;
    std::vector<CommandReply> replies;
    std::vector<ReactionTrigger> triggers;
    std::vector<FeederEvent> events;
    std::vector<ProgressSave> saves;
    std::optional<std::string> save_error;  // what the state store answers
};

bool is_hold(const autopilot::AutopilotRequest& r) {
    return is_state_change(r, autopilot::VehicleState::Parking);
}

bool is_auto(const autopilot::AutopilotRequest& r) {
    return is_state_change(r, autopilot::VehicleState::WaypointNavigation);
}

/// The state change the vehicle was last asked for: Parking, WaypointNavigation, or Unknown when none.
autopilot::VehicleState last_state_asked(const Rig& rig) {
    for (auto it = rig.requests.rbegin(); it != rig.requests.rend(); ++it) {
        if (const auto* s = std::get_if<autopilot::RequestStateChange>(&it->op)) {
            return s->state;
        }
    }
    return autopilot::VehicleState::Unknown;
}

TEST(FlightplanController, LoadUploadsTheWindowStartsTheVehicleAndAnswersOnceConfirmed) {
    Rig rig;
    rig.ready();
    const auto id = rig.load(plan_text());
    ASSERT_FALSE(rig.requests.empty());
    EXPECT_TRUE(is_upload(rig.requests.front()));
    const auto& items = std::get<autopilot::UploadMission>(rig.requests.front().op).items;
    ASSERT_GE(items.size(), 2u);
    EXPECT_DOUBLE_EQ(items[1].lat, 41.0001);  // after the slot before the plan's first waypoint
    EXPECT_TRUE(rig.replies_to(id).empty()) << "answered before the autopilot confirmed";
    rig.confirm_all();
    EXPECT_EQ(rig.count(is_auto), 1u);
    EXPECT_EQ(rig.count(is_hold), 0u);
    const auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies.front().status, Status::Ok);
    EXPECT_EQ(replies.front().result["state"], "running");
    EXPECT_EQ(rig.state(), "running");
}

TEST(FlightplanController, ThePlanSectionGoesOutOnlyWhenWhatItShowsChanged) {
    Rig r;
    const auto check = [&r](bool force) {
        r.c.publish_status(force);
        auto s = r.c.poll_status();
        EXPECT_TRUE(s.has_value());  // the PlanProgress variable goes out every time
        return s && s->section ? std::optional<std::string>((*s->section)["state"].get<std::string>())
                               : std::nullopt;
    };
    EXPECT_EQ(check(false), std::nullopt);  // unchanged since the start published it
    EXPECT_EQ(check(true), "none");
    r.run_plan("hold", true);               // the changes went out as they came (drained)
    EXPECT_EQ(check(false), std::nullopt);  // nothing new since
    r.c.on_link(false, r.now);              // lost: the reaction's countdown shows nowhere yet
    r.drain();
    EXPECT_EQ(check(false), std::nullopt);
    r.advance(seconds(21));
    EXPECT_EQ(r.count(is_hold), 1u);
    EXPECT_EQ(check(true), r.state());
}

TEST(FlightplanController, ALoadWhileTheAutopilotIsNotReadyIsKeptAndDoneAPauseIsNot) {
    Rig rig;
    const auto id = rig.load(plan_text());
    EXPECT_TRUE(rig.requests.empty()) << "nothing is sent to an autopilot that is not ready";
    const auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies.front().status, Status::Ok) << replies.front().error;
    EXPECT_EQ(replies.front().result.value("kept", false), true) << replies.front().result.dump();
    EXPECT_EQ(replies.front().result.value("state", ""), "running") << replies.front().result.dump();
    // A pause is done only when the board does it: the vehicle may still be driving.
    rig.c.pause(rig.next_id, rig.now);
    rig.drain();
    const auto paused = rig.replies_to(rig.next_id++);
    ASSERT_EQ(paused.size(), 1u);
    EXPECT_EQ(paused.front().status, Status::Failed);
    EXPECT_EQ(
        paused.front().error,
        "plan.pause: the autopilot is not ready; the board has not done it (it is kept, and done when it "
        "is ready)");
    // The plan is kept, paused, and goes to the autopilot once it is there.
    rig.ready();
    rig.confirm_all();
    EXPECT_EQ(rig.count(is_upload), 1u);
    EXPECT_GE(rig.count(is_hold), 1u);
    EXPECT_EQ(rig.state(), "paused");
}

TEST(FlightplanController, AnAutopilotLostWhileALoadWaitsForItKeepsThePlanAndSaysSo) {
    Rig rig;
    rig.ready();
    const auto id = rig.load(plan_text());
    ASSERT_TRUE(rig.replies_to(id).empty()) << "waiting for the board";
    rig.not_ready();
    const auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies.front().status, Status::Ok) << replies.front().error;
    EXPECT_EQ(replies.front().result.value("kept", false), true);
    // Once the board is there again, the kept plan goes to it.
    const auto uploads = rig.count(is_upload);
    rig.ready(1, 0);
    EXPECT_GT(rig.count(is_upload), uploads);
}

TEST(FlightplanController, ACommandTheAutopilotDoesNotConfirmTimesOutOnce) {
    PlanControllerConfig config;
    config.command_timeout = seconds(5);
    Rig rig(config);
    rig.ready();
    const auto id = rig.load(plan_text());
    EXPECT_LE(rig.c.poll_timeout(), rig.now + seconds(5));
    rig.advance(milliseconds(4900));
    EXPECT_TRUE(rig.replies_to(id).empty());
    rig.advance(milliseconds(200));
    auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies.front().status, Status::Failed);
    EXPECT_NE(replies.front().error.find("plan.load: the autopilot did not confirm in time"),
              std::string::npos)
        << replies.front().error;
    rig.confirm_all();  // late confirmations: no second answer
    EXPECT_EQ(rig.replies_to(id).size(), 1u);
}

TEST(FlightplanController, BadAppendsAndSkipsAreAnsweredAtOnceWithoutTouchingTheVehicle) {
    Rig rig;
    rig.ready();
    EXPECT_FALSE(rig.c.prepare_load(7, LoadRequest{plan_text(), "more.yaml", true}).has_value());
    rig.c.skip(8, std::uint64_t{1}, rig.now);
    EXPECT_FALSE(rig.c.prepare_load(9, LoadRequest{"plan: [", "bad.yaml", false}).has_value());
    rig.drain();
    ASSERT_EQ(rig.replies.size(), 3u);
    EXPECT_EQ(rig.replies[0].status, Status::Refused);
    EXPECT_EQ(rig.replies[1].status, Status::Refused);
    EXPECT_EQ(rig.replies[2].status, Status::BadRequest);
    EXPECT_TRUE(rig.requests.empty());
}

TEST(FlightplanController, APlanLoadedOnALowBatteryAtRestReactsAtOnce) {
    // Telemetry reaches the controller only when it changes: a vehicle at rest on a low battery sends no more
    // after the first sample, and the plan loaded afterwards must still see it.
    Rig rig;
    rig.ready();
    autopilot::Telemetry t;
    t.battery_remaining = 18;
    t.position = autopilot::Position{41.0, 2.0, 0.0};
    rig.c.on_telemetry(t, rig.now);
    rig.drain();
    std::string text = plan_text();
    text.replace(text.find("    link_loss"), 0, "    low_battery: {below: 25, action: hold}\n");
    rig.load(text);
    ASSERT_EQ(rig.triggers.size(), 1u);
    EXPECT_EQ(rig.triggers.front().cause, ReactionTrigger::Cause::LowBattery);
}

TEST(FlightplanController, LinkLostForTheConfiguredTimeHoldsTheVehicle) {
    Rig rig;
    rig.run_plan("hold", true);
    rig.c.on_link(false, rig.now);
    rig.drain();
    rig.advance(seconds(19));
    EXPECT_TRUE(rig.triggers.empty());
    EXPECT_EQ(rig.count(is_hold), 0u);
    rig.advance(seconds(2));
    ASSERT_EQ(rig.triggers.size(), 1u);
    EXPECT_EQ(rig.triggers.front().cause, ReactionTrigger::Cause::LinkLoss);
    EXPECT_EQ(rig.count(is_hold), 1u);
    rig.confirm_all();
    EXPECT_EQ(rig.state(), "paused");
    EXPECT_EQ(rig.c.progress_json()["reaction"], "link-loss: hold (ground link down for 20 s)");
}

TEST(FlightplanController, ALinkNeverSeenUpIsNotLost) {
    Rig rig;
    rig.run_plan("hold", false);
    rig.advance(seconds(60));
    EXPECT_TRUE(rig.triggers.empty());
    EXPECT_EQ(rig.count(is_hold), 0u);
}

TEST(FlightplanController, LinkLossReturnsHomeWhenThePlanSaysSo) {
    Rig rig;
    rig.run_plan("return_home", true);
    const auto sent = rig.requests.size();
    rig.c.on_link(false, rig.now);
    rig.drain();
    rig.advance(seconds(21));
    ASSERT_EQ(rig.triggers.size(), 1u);
    EXPECT_TRUE(rig.c.returning_home());
    // The way home replaces the plan in the window (after the barrier that keeps the vehicle from driving on
    // past its current target meanwhile).
    rig.confirm_all();
    bool home_written = false;
    for (auto i = sent; i < rig.requests.size(); ++i) {
        if (const auto* w = std::get_if<autopilot::WriteMissionItems>(&rig.requests[i].op)) {
            for (const auto& item : w->items) {
                home_written = home_written || (item.kind == autopilot::MissionItem::Kind::Waypoint &&
                                                item.lat == 41.0 && item.lon == 2.0);
            }
        }
    }
    EXPECT_TRUE(home_written);
    EXPECT_EQ(rig.c.progress_json()["reaction"], "link-loss: return home (ground link down for 20 s)");
    // A plan.append is refused on the way home.
    EXPECT_FALSE(rig.c.prepare_load(50, LoadRequest{plan_text(), "more.yaml", true}).has_value());
    rig.drain();
    ASSERT_EQ(rig.replies_to(50).size(), 1u);
    EXPECT_EQ(rig.replies_to(50).front().status, Status::Refused);
}

TEST(FlightplanController, AnAutopilotThatRebootsMidPlanGetsTheWindowAgain) {
    Rig rig;
    rig.ready();
    rig.load(plan_text());
    rig.confirm_all();
    ASSERT_EQ(rig.count(is_upload), 1u);
    rig.c.on_reached(1, rig.now);
    rig.drain();
    rig.c.on_rebooted(rig.now);
    rig.drain();
    EXPECT_EQ(rig.count(is_upload), 2u);
    rig.confirm_all();
    EXPECT_EQ(rig.state(), "running");
    EXPECT_EQ(last_state_asked(rig), autopilot::VehicleState::WaypointNavigation);
}

TEST(FlightplanController, AnAutopilotBackWithTheSameCountsKeepsItsWindowAReconnectedOneDoesNot) {
    Rig rig;
    rig.ready(0, 0);
    rig.load(plan_text());
    rig.confirm_all();
    ASSERT_EQ(rig.count(is_upload), 1u);
    rig.not_ready();
    rig.ready(0, 0);  // it only went silent
    EXPECT_EQ(rig.count(is_upload), 1u);
    rig.not_ready();
    rig.ready(1, 0);  // the port was reopened: what it holds is unknown
    EXPECT_EQ(rig.count(is_upload), 2u);
}

TEST(FlightplanController, PauseThenResumeLeavesTheRunningPlanInAuto) {
    Rig rig;
    rig.ready();
    rig.load(plan_text());
    rig.confirm_all();
    rig.c.pause(20, rig.now);
    rig.drain();
    EXPECT_EQ(last_state_asked(rig), autopilot::VehicleState::Parking);
    rig.confirm_all();
    ASSERT_EQ(rig.replies_to(20).size(), 1u);
    EXPECT_EQ(rig.replies_to(20).front().status, Status::Ok);
    EXPECT_EQ(rig.state(), "paused");
    rig.c.resume_plan(21, rig.now);
    rig.drain();
    rig.confirm_all();
    ASSERT_EQ(rig.replies_to(21).size(), 1u);
    EXPECT_EQ(rig.replies_to(21).front().status, Status::Ok);
    EXPECT_EQ(rig.state(), "running");
    EXPECT_EQ(last_state_asked(rig), autopilot::VehicleState::WaypointNavigation);
    rig.advance(seconds(10));
    EXPECT_EQ(last_state_asked(rig), autopilot::VehicleState::WaypointNavigation)
        << "nothing parks the running plan afterwards";
}

TEST(FlightplanController, ProgressIsKeptOnceAndAWayHomeLeavesThePlanSavedAsPaused) {
    Rig rig(with_a_state_store());
    rig.run_plan("return_home", true);
    ASSERT_FALSE(rig.saves.empty());
    EXPECT_EQ(rig.saves.back().progress.state, PlanState::Running);
    for (std::size_t i = 1; i < rig.saves.size(); ++i) {
        EXPECT_FALSE(rig.saves[i].progress == rig.saves[i - 1].progress) << "the same point saved twice";
    }
    const auto before = rig.saves.size();
    rig.c.on_link(false, rig.now);
    rig.drain();
    rig.advance(seconds(21));
    rig.confirm_all();
    ASSERT_EQ(rig.saves.size(), before + 1) << "only the paused point: the way home is not a plan to resume";
    EXPECT_EQ(rig.saves.back().progress.state, PlanState::Paused);
    EXPECT_EQ(rig.saves.back().progress.next_index, rig.saves[before - 1].progress.next_index);
}

TEST(FlightplanController, AProgressTheStoreCannotKeepIsThePlansError) {
    Rig rig(with_a_state_store());
    rig.save_error = "disk full";
    rig.run_plan("hold", true);
    EXPECT_EQ(rig.c.progress_json()["error"], "disk full");
}

TEST(FlightplanController, AfterAFailedSaveAWayHomeStillLeavesTheLastSavedPointPaused) {
    Rig rig(with_a_state_store());
    rig.run_plan("return_home", true);
    ASSERT_FALSE(rig.saves.empty());
    const SavedProgress written = rig.saves.back().progress;
    ASSERT_EQ(written.state, PlanState::Running);
    rig.save_error = "disk full";  // the store refuses from now on
    rig.c.pause(rig.next_id++, rig.now);
    rig.drain();
    rig.confirm_all();
    ASSERT_EQ(rig.saves.back().progress.state, PlanState::Paused)
        << "the paused point was tried, and refused";
    rig.c.resume_plan(rig.next_id++, rig.now);
    rig.drain();
    rig.confirm_all();
    const auto before = rig.saves.size();
    rig.c.on_link(false, rig.now);
    rig.drain();
    rig.advance(seconds(21));
    rig.confirm_all();
    ASSERT_GT(rig.saves.size(), before) << "a way home keeps the restart point";
    const auto& paused = rig.saves.back().progress;
    EXPECT_EQ(paused.state, PlanState::Paused);
    EXPECT_EQ(paused.next_index, written.next_index) << "the point the store last kept";
}

constexpr const char* kShapePlan = R"(plan:
  name: shape
  no_fly:
    - name: pond
      polygon: [[41.0100, 2.0100], [41.0100, 2.0110], [41.0090, 2.0110]]
  elements:
    - waypoint: {name: start, lat: 41.0001, lon: 2.0001}
    - hold: {seconds: 5}
    - speed: 1.0
    - repeat:
        count: forever
        elements:
          - scan: {rectangle: {sw: [41.0002, 2.0002], ne: [41.0006, 2.0008]}, spacing: 6}
          - hold: {lat: 41.0001, lon: 2.0001, until_released: true}
  blocks:
    - name: lost-link
      elements:
        - waypoint: {lat: 41.0, lon: 2.0}
)";

std::size_t points_in(const Json& geometry) {
    std::size_t n = 0;
    for (const auto& e : geometry["elements"]) {
        n += e["points"].size() + (e.contains("lines") ? e["lines"].size() : 0);
    }
    for (const auto& z : geometry["no_fly"]) {
        n += z["points"].size();
    }
    return n;
}

TEST(FlightplanController, GeometryWithoutAPlanIsEmpty) {
    Rig rig;
    const auto g = rig.c.geometry(2000);
    EXPECT_TRUE(g["name"].is_null());
    EXPECT_TRUE(g["elements"].empty());
    EXPECT_TRUE(g["no_fly"].empty());
}

TEST(FlightplanController, GeometryDrawsEveryPositionedElementOnceEvenInAnEndlessLoop) {
    Rig rig;
    rig.ready();
    rig.load(kShapePlan);
    rig.confirm_all();
    const auto g = rig.c.geometry(2000);
    EXPECT_EQ(g["name"], "shape");
    EXPECT_FALSE(g["truncated"].get<bool>());
    EXPECT_TRUE(g["generation"].is_number());
    ASSERT_EQ(g["elements"].size(), 5u) << g.dump(1);
    const auto& e = g["elements"];
    EXPECT_EQ(e[0]["kind"], "waypoint");
    EXPECT_EQ(e[0]["name"], "start");
    EXPECT_EQ(e[0]["points"], Json::parse("[[41.0001, 2.0001]]"));
    EXPECT_EQ(e[1]["kind"], "hold");
    EXPECT_EQ(e[1]["hold_s"], 5.0);
    EXPECT_EQ(e[1]["points"], e[0]["points"]) << "a hold without a position holds where the last one ends";
    EXPECT_EQ(e[2]["kind"], "scan");
    EXPECT_TRUE(e[2]["closed"].get<bool>());
    EXPECT_EQ(e[2]["points"].size(), 4u) << "the rectangle's outline";
    EXPECT_GE(e[2]["lines"].size(), 4u) << "the lines across it, two ends each";
    EXPECT_EQ(e[2]["lines"].size() % 2, 0u);
    EXPECT_TRUE(e[3]["hold_s"].is_null()) << "until released";
    EXPECT_NE(e[4]["path"].get<std::string>().find("blocks"), std::string::npos) << e[4]["path"];
    ASSERT_EQ(g["no_fly"].size(), 1u);
    EXPECT_EQ(g["no_fly"][0]["name"], "pond");
    EXPECT_EQ(g["no_fly"][0]["points"].size(), 3u);
}

TEST(FlightplanController, GeometrySaysWhenItLeftPointsOut) {
    Rig rig;
    rig.ready();
    rig.load(kShapePlan);
    rig.confirm_all();
    const auto g = rig.c.geometry(6);
    EXPECT_TRUE(g["truncated"].get<bool>());
    EXPECT_EQ(points_in(g), 6u);
    EXPECT_FALSE(rig.c.geometry(1000)["truncated"].get<bool>());
}

TEST(FlightplanController, StopFailsTheWaitingCommands) {
    Rig rig;
    rig.ready();
    const auto id = rig.load(plan_text());
    rig.c.stop("the daemon is stopping");
    rig.drain();
    const auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_EQ(replies.front().error, "plan.load: the daemon is stopping");
}

// A board that will not arm (ArduPilot Rover 4.x, ARMING_REQUIRE 1, a check failing): the driver's request
// for WAYPOINT_NAVIGATION ends Refused with the board's words, and the plan fails with them.
TEST(FlightplanController, AnAutopilotThatRefusesToArmFailsThePlanWithItsReasonAndHoldsTheVehicle) {
    Rig rig;
    rig.ready();
    const auto id = rig.load(plan_text());
    for (int guard = 0; guard < 100 && !rig.pending.empty(); ++guard) {
        const auto call = rig.pending.front();
        rig.pending.erase(rig.pending.begin());
        rig.now += milliseconds(50);
        autopilot::RequestDone done;
        if (is_auto(call.request)) {
            done.kind = autopilot::RequestKind::SetState;
            done.result = autopilot::RequestResult::Refused;
            done.detail = "the autopilot refused to arm (MAV_RESULT_FAILED): Arm: Need Position Estimate";
        }
        rig.c.on_request_done(call.id, done, rig.now);
        rig.drain();
    }
    EXPECT_EQ(rig.state(), "failed");
    const auto plan = rig.c.progress_json();
    ASSERT_TRUE(plan["error"].is_string()) << plan.dump();
    EXPECT_NE(plan["error"].get<std::string>().find("Arm: Need Position Estimate"), std::string::npos)
        << plan.dump();
    EXPECT_EQ(std::count_if(rig.events.begin(), rig.events.end(),
                            [](const FeederEvent& e) { return e.kind == FeederEvent::Kind::PlanFailed; }),
              1);
    const auto replies = rig.replies_to(id);
    ASSERT_EQ(replies.size(), 1u);
    EXPECT_NE(replies.front().status, Status::Ok);
    EXPECT_EQ(rig.count(is_auto), 1u) << "not asked again";
    EXPECT_EQ(last_state_asked(rig), autopilot::VehicleState::Parking);
}

TEST(FlightplanController, ADonePlanShowsNoInterruptionARunningOneShowsTheLast) {
    FeederProgress p;
    p.interruption = "the autopilot left AUTO for HOLD by itself";
    p.state = PlanState::Running;
    EXPECT_EQ(PlanController::shown_interruption(p), p.interruption);
    p.state = PlanState::Interrupted;
    EXPECT_EQ(PlanController::shown_interruption(p), p.interruption);
    p.state = PlanState::Done;
    EXPECT_EQ(PlanController::shown_interruption(p), "");
}

}  // namespace
}  // namespace airseg::flightplan
