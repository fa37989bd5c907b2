#include "services/status/status_service.hpp"

#include <spdlog/spdlog.h>

#include "services/common/command_record.hpp"
#include "services/status/status_document.hpp"

namespace airseg::status {

StatusService::StatusService(ServiceContext& ctx, StatusServiceConfig config)
    : Service("status", ctx),
      config_(std::move(config)),
      server_(strand(), ctx.commands),
      refresh_timer_(strand(), ctx.wakes),
      socket_timer_(strand()),
      started_at_(SteadyClock::now()) {}

nlohmann::json StatusService::document() const {
    const double uptime = std::chrono::duration<double>(SteadyClock::now() - started_at_).count();
    for (auto& [name, render] : unrendered_) {
        sections_[name] = render();
    }
    unrendered_.clear();
    sections_["status"] = own_section();
    return build_document(ctx_.health.snapshot(), sections_, uptime);
}

namespace {

/// The at-most-once record (command_record.hpp): commands run under a request id, and those it spared.
nlohmann::json request_ids_json(const CommandRecordStats& r) {
    return {{"recorded", r.recorded},    {"replayed", r.replayed}, {"joined", r.joined},
            {"conflicts", r.conflicts},  {"entries", r.entries},   {"forgotten_early", r.forgotten_early},
            {"unrecorded", r.unrecorded}};
}

}  // namespace

nlohmann::json StatusService::own_section() const {
    const auto s = server_.stats();
    return {{"local_socket",
             {{"clients", s.clients},
              {"accepted", s.accepted},
              {"refused", s.refused},
              {"evicted", s.evicted},
              {"closed_slow", s.closed_slow},
              {"closed_idle", s.closed_idle}}},
            {"request_ids", request_ids_json(ctx_.commands.record_stats())},
            {"log_lines_held", LimitedLog::held_everywhere()}};
}

void StatusService::on_tick(TimePoint now) {
    server_.flush_log(now);
}

void StatusService::on_start() {
    sections_sub_ = ctx_.bus.subscribe<StatusSection>(strand(), [this](const StatusSection& s) {
        if (s.render) {
            unrendered_[s.name] = s.render;
        } else {
            unrendered_.erase(s.name);
            sections_[s.name] = s.value;
        }
        if (s.name == "plan") {
            publish_summary();  // the only section the line shows; health changes go with the refresh
        }
    });
    ctx_.commands.add("status", strand(), Role::Monitor, [this](const Json&, CommandDispatcher::Reply reply) {
        reply(CommandResult::ok(document()));
    });
    do_open_socket();
    do_refresh();
}

void StatusService::on_stop() {
    refresh_timer_.cancel();
    socket_timer_.cancel();
    sections_sub_.reset();
    server_.close();
}

void StatusService::do_open_socket() {
    const std::string error = server_.open(config_.socket_path, config_.socket_mode);
    if (error.empty()) {
        spdlog::info("status: serving {}", config_.socket_path);
        set_health(Health::Up);
        return;
    }
    // Without the socket the daemon still flies; it says so and tries again.
    set_health(Health::Degraded, error);
    socket_timer_.expires_after(config_.socket_retry);
    socket_timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec) {
            do_open_socket();
        }
    });
}

void StatusService::do_refresh() {
    publish_summary();
    // On the grid the services' progress ticks use, and up to half a period late to share a wake-up
    // (time.hpp, wake_sharing.hpp).
    refresh_timer_.arm(next_on_grid(SteadyClock::now(), config_.refresh_interval),
                       config_.refresh_interval / 2, [this] { do_refresh(); });
}

void StatusService::publish_summary() {
    auto line = summary_line(ctx_.health.snapshot(), sections_);
    if (line != last_summary_) {
        last_summary_ = line;
        ctx_.bus.publish_latest(StatusLine{std::move(line)});
    }
}

}  // namespace airseg::status
