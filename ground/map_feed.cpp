#include "ground/map_feed.hpp"

#include <spdlog/spdlog.h>

namespace airseg::ground {

namespace proto = groundlink::protocol;
using Json = nlohmann::json;

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
        map_.add_event(e->text);
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
    hub_.command({{"cmd", "plan.geometry"}, {"max_points", kPlanPoints}}, [this](Json answer) {
        fetching_ = false;
        if (stopped_) {
            return;
        }
        if (answer.value("ok", false)) {
            map_.set_plan(answer["result"]);
        } else {
            spdlog::warn("ground hub: the plan's shape for the map: {}", answer.value("error", "no answer"));
        }
        if (fetch_again_) {
            fetch_again_ = false;
            refresh_plan();
        }
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
