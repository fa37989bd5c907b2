#include "services/flightplan/flightplan_service.hpp"

#include <spdlog/spdlog.h>

#include "services/flightplan/resume.hpp"
#include "services/groundlink/link_state.hpp"
#include "services/status/status_messages.hpp"

namespace airseg::flightplan {

namespace {

PlanControllerConfig controller_config(const FlightplanServiceConfig& c) {
    PlanControllerConfig out;
    out.feeder = c.feeder;
    out.load = c.load;
    out.keeps_progress = !c.state_dir.empty();
    out.command_timeout = c.command_timeout;
    return out;
}

CommandStatus to_command_status(CommandReply::Status s) {
    switch (s) {
        case CommandReply::Status::Ok:
            return CommandStatus::Ok;
        case CommandReply::Status::Refused:
            return CommandStatus::Refused;
        case CommandReply::Status::BadRequest:
            return CommandStatus::BadRequest;
        case CommandReply::Status::Failed:
            break;
    }
    return CommandStatus::Failed;
}

spdlog::level::level_enum to_spdlog(LogLine::Level level) {
    switch (level) {
        case LogLine::Level::Debug:
            return spdlog::level::debug;
        case LogLine::Level::Info:
            return spdlog::level::info;
        case LogLine::Level::Warn:
            return spdlog::level::warn;
        case LogLine::Level::Error:
            break;
    }
    return spdlog::level::err;
}

}  // namespace

FlightplanService::FlightplanService(ServiceContext& ctx, FlightplanServiceConfig config)
    : Service("flightplan", ctx),
      config_(std::move(config)),
      controller_(controller_config(config_)),
      timer_(strand(), ctx.wakes),
      status_timer_(strand(), ctx.wakes) {
    if (!config_.state_dir.empty()) {
        store_.emplace(config_.state_dir, config_.durability);
    }
    register_commands();
}

FlightplanService::~FlightplanService() = default;

void FlightplanService::on_start() {
    calls_.emplace();
    running_ = true;
    auto& bus = ctx_.bus;
    subscriptions_.push_back(
        bus.subscribe<autopilot::AutopilotStatus>(strand(), [this](const autopilot::AutopilotStatus& s) {
            controller_.on_autopilot_status(s, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::Telemetry>(strand(), [this](const autopilot::Telemetry& t) {
            controller_.on_telemetry(t, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::WaypointReached>(strand(), [this](const autopilot::WaypointReached& r) {
            controller_.on_reached(r.seq, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(bus.subscribe<autopilot::MissionCurrentChanged>(
        strand(), [this](const autopilot::MissionCurrentChanged& c) {
            controller_.on_current(c.seq, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::MissionItemStored>(strand(), [this](const autopilot::MissionItemStored& s) {
            controller_.on_item_stored(s.slot, s.item, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(bus.subscribe<autopilot::GroundStationMission>(
        strand(), [this](const autopilot::GroundStationMission& m) { on_ground_station_mission(m); }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::AutopilotRebooted>(strand(), [this](const autopilot::AutopilotRebooted&) {
            controller_.on_rebooted(SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(
        bus.subscribe<autopilot::ModeChanged>(strand(), [this](const autopilot::ModeChanged& m) {
            controller_.on_mode_changed(m, SteadyClock::now());
            flush();
        }));
    subscriptions_.push_back(
        bus.subscribe<groundlink::LinkState>(strand(), [this](const groundlink::LinkState& s) {
            controller_.on_link(s.up, SteadyClock::now());
            flush();
        }));
    if (store_) {
        // Whatever the stored state holds, the service comes up: a plan that cannot be resumed is set aside,
        // never met again at the next start (no restart loop, no deaf daemon).
        ResumeResult resumed;
        try {
            resumed = resume_from(store_->load(), config_.load);
        } catch (const std::exception& e) {
            resumed = ResumeResult{};
            resumed.problems.push_back(std::string("stored plan cannot be resumed: ") + e.what() +
                                       "; set aside");
            resumed.set_aside = true;
        }
        if (resumed.set_aside) {
            for (auto& problem : store_->set_aside_plan()) {
                resumed.problems.push_back(std::move(problem));
            }
        }
        controller_.resume(std::move(resumed), SteadyClock::now());
    }
    set_health(Health::Up);
    controller_.start(SteadyClock::now());
    flush();
    schedule_status();
}

void FlightplanService::on_stop() {
    running_ = false;
    subscriptions_.clear();
    calls_.reset();
    timer_.cancel();
    status_timer_.cancel();
    controller_.stop("the daemon is stopping");
    flush();
}

void FlightplanService::on_tick(TimePoint now) {
    log_.flush(now);
}

void FlightplanService::call(AutopilotCall c) {
    if (!calls_) {
        return;  // stopped: nothing more goes to the autopilot
    }
    c.request.reply = Reply<autopilot::RequestDone>(
        strand(), *calls_, autopilot::not_answered(), [this, id = c.id](const autopilot::RequestDone& d) {
            controller_.on_request_done(id, d, SteadyClock::now());
            flush();
        });
    ctx_.bus.publish(std::move(c.request));
}

void FlightplanService::flush() {
    while (auto out = controller_.poll_output()) {
        std::visit(
            [this](auto&& m) {
                using T = std::decay_t<decltype(m)>;
                if constexpr (std::is_same_v<T, AutopilotCall>) {
                    call(std::move(m));
                } else {
                    ctx_.bus.publish(std::move(m));
                }
            },
            std::move(*out));
    }
    while (auto save = controller_.poll_save()) {
        controller_.on_saved(*save, store_ ? store_->save_progress(save->progress) : std::nullopt);
    }
    while (auto r = controller_.poll_reply()) {
        const auto it = replies_.find(r->id);
        if (it == replies_.end()) {
            continue;
        }
        auto reply = std::move(it->second);
        replies_.erase(it);
        reply(r->status == CommandReply::Status::Ok
                  ? CommandResult::ok(std::move(r->result))
                  : CommandResult::fail(to_command_status(r->status), std::move(r->error)));
    }
    while (auto line = controller_.poll_log()) {
        const auto level = to_spdlog(line->level);
        const auto name = spdlog::level::to_string_view(level);
        log_.log(std::string(kPrefix) + "(" + std::string(name.data(), name.size()) + " lines)",
                 SteadyClock::now(), level, "{}{}", kPrefix, line->text);
    }
    while (auto s = controller_.poll_status()) {
        ctx_.bus.publish_latest(s->progress);
        if (s->section) {
            ctx_.bus.publish(status::StatusSection{"plan", std::move(*s->section), {}});
        }
    }
    if (!running_) {
        return;
    }
    timer_.arm(controller_.poll_timeout(), [this] {
        if (!running_) {
            return;
        }
        controller_.handle_timeout(SteadyClock::now());
        flush();
    });
}

void FlightplanService::schedule_status() {
    // On the grid the services' progress ticks use, and up to half a period late to share a wake-up
    // (time.hpp, wake_sharing.hpp).
    status_timer_.arm(next_on_grid(SteadyClock::now(), config_.status_period), config_.status_period / 2,
                      [this] {
                          if (!running_) {
                              return;
                          }
                          controller_.publish_status(false);
                          flush();
                          schedule_status();
                      });
}

}  // namespace airseg::flightplan
