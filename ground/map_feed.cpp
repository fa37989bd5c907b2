#include "ground/map_feed.hpp"

#include <spdlog/spdlog.h>

#include "groundside/event_wording.hpp"

namespace airseg::ground {

namespace proto = groundlink::protocol;
using Json = nlohmann::json;

namespace {

/// The plan's shape (plan.geometry) with the counts of plan.show: "waypoints" (the expanded plan's count,
/// null when endless) and "top" (its top-level elements: path, kind, name, waypoints).

void with_counts(Json& geometry, const Json& show) {
    Json top = Json::array();
    std::uint64_t total = 0;
    bool counted = true;
    const auto elements = show.find("elements");
    if (elements == show.end() || !elements->is_array()) {
        return;
    }
    for (const auto& e : *elements) {
        const auto n = e.find("waypoints");
        if (n != e.end() && n->is_number_unsigned()) {
            total += n->get<std::uint64_t>();
        } else {
            counted = false;  // an endless repeat: no count
        }
        top.push_back({{"path", e.value("path", Json())},
                       {"kind", e.value("kind", Json())},
                       {"name", e.value("name", Json())},
                       {"waypoints", n != e.end() ? *n : Json()}});
    }
    geometry["top"] = std::move(top);
    geometry["waypoints"] = counted ? Json(total) : Json();
}

}  // namespace

MapFeed::MapFeed(asio::any_io_executor strand, Hub& hub, MapConfig config)
    : hub_(hub),
      map_(strand, std::move(config),
           [&hub](Json request, std::function<void(Json)> done) {
               hub.command(std::move(request), std::move(done));
           }),
      timer_(strand) {}

std::string MapFeed::start() {
    if (auto error = map_.start(); !error.empty()) {
        return error;
    }
    hub_.add_listener([this](const proto::Message& m) { on_vehicle(m); });
    hub_.add_result_listener([this](const std::string& cmd, const Json& answer) {
        if ((cmd == "plan.load" || cmd == "plan.append") && answer.value("ok", false)) {
            refresh_plan();
        }
    });
    tick();
    return {};
}

void MapFeed::stop() {
    stopped_ = true;
    timer_.cancel();
    map_.stop();
}

void MapFeed::on_vehicle(const proto::Message& message) {
    if (const auto* t = std::get_if<proto::Telemetry>(&message)) {
        map_.add_position(*t, std::chrono::system_clock::now());
        if (plan_state_ != t->plan_state) {
            plan_state_ = t->plan_state;
            refresh_plan();
        }
    } else if (const auto* e = std::get_if<proto::Event>(&message)) {
        map_.add_event(*e);
        if (groundside::announces_plan(e->text)) {
            refresh_plan();  // another plan took over, or one was appended: the state alone does not change
        }
    }
}

void MapFeed::refresh_plan() {
    if (stopped_) {
        return;
    }
    if (fetching_) {
        fetch_again_ = true;  // the answer on its way may predate the change
        return;
    }
    fetching_ = true;
    const auto done = [this] {
        fetching_ = false;
        if (fetch_again_) {
            fetch_again_ = false;
            refresh_plan();
        }
    };
    hub_.command({{"cmd", "plan.geometry"}, {"max_points", kPlanPoints}}, [this, done](Json answer) {
        if (stopped_) {
            return;
        }
        if (!answer.value("ok", false)) {
            spdlog::warn("ground hub: the plan's shape for the map: {}", answer.value("error", "no answer"));
            done();
            return;
        }
        // Then the plan's counts (plan.show): the waypoints in plan terms ("waypoint 4 of 12") and the names
        // of its top-level elements. Without them the map still draws the shape.
        hub_.command({{"cmd", "plan.show"}},
                     [this, done, geometry = std::move(answer["result"])](Json show) mutable {
                         if (stopped_) {
                             return;
                         }
                         if (show.value("ok", false) && show["result"].is_object()) {
                             with_counts(geometry, show["result"]);
                         }
                         map_.set_plan(geometry);
                         done();
                     });
    });
}

void MapFeed::tick() {
    if (stopped_) {
        return;
    }
    const auto link = hub_.link_stats();
    map_.set_link(link);
    const bool up = link.value("link", "down") == "up";
    if (up && !link_up_) {
        refresh_plan();
    }
    link_up_ = up;
    timer_.expires_after(std::chrono::seconds(1));
    timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec) {
            tick();
        }
    });
}

}  // namespace airseg::ground
