#include "daemon/app.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "base/utf8.hpp"
#include "daemon/autopilot_commands.hpp"
#include "daemon/autopilot_setup.hpp"
#include "daemon/autopilot_status.hpp"
#include "daemon/autopilot_status_led.hpp"
#include "daemon/config_loader.hpp"
#include "daemon/flightplan_setup.hpp"
#include "daemon/logging.hpp"
#include "daemon/systemd_notifier.hpp"
#include "hal/gpio_libgpiod.hpp"
#include "services/autopilot/autopilot_service.hpp"
#include "services/common/wake_sharing.hpp"
#include "services/flightplan/flightplan_service.hpp"
#include "services/groundlink/groundlink_messages.hpp"
#include "services/groundlink/groundlink_service.hpp"
#include "services/status/status_messages.hpp"
#include "services/status/status_service.hpp"

namespace airseg::daemon {

namespace {

groundlink::TelemetrySchedulerConfig telemetry_config(const Config& c) {
    groundlink::TelemetrySchedulerConfig t;
    for (auto kind : groundlink::kAllTelemetryKinds) {
        const auto it = c.groundlink.telemetry_rates.find(groundlink::to_string(kind));
        if (it != c.groundlink.telemetry_rates.end()) {
            t.rate_hz[static_cast<std::size_t>(kind)] = it->second;
        }
    }
    t.budget_share = c.groundlink.telemetry_budget_share;
    t.min_hz = c.groundlink.telemetry_min_hz;
    return t;
}

}  // namespace

class App::Impl {
  public:
    Impl(CliOptions options, Config config)
        : options_(std::move(options)),
          config_(std::move(config)),
          strand_(asio::make_strand(control_io_)),
          adapters_strand_(asio::make_strand(io_)),
          signals_(strand_, SIGTERM, SIGINT, SIGHUP),
          watchdog_timer_(strand_),
          context_{io_, bus_, health_, commands_, progress_interval(), &wakes_} {}

    int run() {
        ensure_state_dir();
        build_services();
        line_sub_ = bus_.subscribe<status::StatusLine>(
            strand_, [this](const status::StatusLine& line) { notifier_.status(line.text); });
        do_signals();
        start_services();
        if (notifier_.watchdog_period()) {
            spdlog::info(
                "systemd: watchdog every {} ms",
                std::chrono::duration_cast<std::chrono::milliseconds>(*notifier_.watchdog_period()).count());
            do_watchdog();
        }
        arm_test_hang();

        // Keeps run() going while services wait on nothing but signals; shutdown() ends it with io_.stop().
        auto work = asio::require(io_.get_executor(), asio::execution::outstanding_work.tracked);
        auto control_work =
            asio::require(control_io_.get_executor(), asio::execution::outstanding_work.tracked);
        // Signals, the watchdog and the notifier run on a thread of their own, apart from the services: a
        // stuck service cannot silence them, however few threads the services have.
        std::thread control([this] { control_io_.run(); });
        const unsigned threads = config_.threads > 0 ? static_cast<unsigned>(config_.threads)
                                                     : std::max(1u, std::thread::hardware_concurrency());
        std::vector<std::thread> pool;
        for (unsigned i = 1; i < threads; ++i) {
            pool.emplace_back([this] { io_.run(); });
        }
        io_.run();
        for (auto& t : pool) {
            t.join();
        }
        control_io_.stop();
        control.join();
        spdlog::info("airsegd: stopped");
        return 0;
    }

  private:
    Duration progress_interval() const {
        // Services tick well inside the watchdog period so one late tick cannot cost a ping.
        Duration interval = std::chrono::seconds(1);
        if (notifier_.watchdog_period()) {
            interval = std::min<Duration>(interval, *notifier_.watchdog_period() / 4);
        }
        return interval;
    }

    void ensure_state_dir() {
        std::error_code ec;
        std::filesystem::create_directories(config_.state_dir, ec);
        if (ec) {
            spdlog::warn("airsegd: state_dir {}: {}; flight plan progress will not survive a restart",
                         config_.state_dir, ec.message());
        }
    }

    void build_services() {
        services_.push_back(std::make_unique<status::StatusService>(
            context_, status::StatusServiceConfig{config_.status.socket, config_.status.socket_mode}));
        auto ap = autopilot_setup(config_);  // already validated by the loader
        if (ap.status_led) {
            if (auto r = gpio_.request(*ap.status_led); r.ok()) {
                status_led_ = std::make_unique<StatusLedDriver>(bus_, adapters_strand_, r.line);
            } else {
                spdlog::warn("status_led: {}; no status LED", r.message);
            }
        }
        hal::GpioFactory* gpio = ap.service.reset_line ? &gpio_ : nullptr;
        services_.push_back(
            std::make_unique<autopilot::AutopilotService>(context_, std::move(ap.service), gpio));
        autopilot_commands_ = std::make_unique<AutopilotCommands>(bus_, commands_, asio::make_strand(io_));
        const auto& gl = config_.groundlink;
        groundlink::GroundlinkServiceConfig g;
        g.mode = gl.mode;
        g.ports = gl.ports;
        g.baud = static_cast<unsigned>(gl.baud);
        g.radio = gl.radio;
        g.reconnect_min = gl.reconnect_min;
        g.reconnect_max = gl.reconnect_max;
        g.key_file = gl.key_file;
        g.insecure = gl.insecure;
        g.udp.bind_address = gl.udp_bind;
        g.udp.bind_port = static_cast<std::uint16_t>(gl.udp_port);
        g.udp.remote_address = gl.udp_remote;
        g.udp.remote_port = static_cast<std::uint16_t>(gl.udp_remote_port);
        g.monitor_key_file = gl.monitor_key_file;
        g.telemetry = telemetry_config(config_);
        g.mavlink_forward = mavlink_forward_setup(config_).config;
        services_.push_back(std::make_unique<groundlink::GroundlinkService>(context_, std::move(g)));
        services_.push_back(
            std::make_unique<flightplan::FlightplanService>(context_, flightplan_setup(config_)));
    }

    void start_services() {
        auto remaining = std::make_shared<std::size_t>(services_.size());
        for (auto& s : services_) {
            s->start([this, remaining] {
                asio::post(strand_, [this, remaining] {
                    if (--*remaining == 0) {
                        // The status service now listens: sections published from here on are kept.
                        autopilot_section_ = std::make_unique<AutopilotStatusSection>(bus_, adapters_strand_);
                        spdlog::info("airsegd {}: all {} services started", AIRSEG_VERSION, services_.size());
                        notifier_.ready();
                    }
                });
            });
        }
    }

    void do_signals() {
        signals_.async_wait([this](boost::system::error_code ec, int signo) {
            if (ec) {
                return;
            }
            if (signo == SIGHUP) {
                reload();
                do_signals();
                return;
            }
            spdlog::info("airsegd: {} received, stopping", signo == SIGTERM ? "SIGTERM" : "SIGINT");
            shutdown();
        });
    }

    void shutdown() {
        if (stopping_) {
            return;
        }
        stopping_ = true;
        notifier_.stopping();
        watchdog_timer_.cancel();
        boost::system::error_code ignored;
        signals_.cancel(ignored);
        line_sub_.reset();
        asio::post(adapters_strand_, [this] {
            autopilot_section_.reset();
            status_led_.reset();
        });
        auto remaining = std::make_shared<std::size_t>(services_.size());
        for (auto& s : services_) {
            s->stop([this, remaining] {
                asio::post(strand_, [this, remaining] {
                    if (--*remaining == 0) {
                        // Everything that must be flushed has been; anything still pending is abandoned.
                        io_.stop();
                    }
                });
            });
        }
    }

    void reload() {
        notifier_.reloading();
        auto result = load_config_file(options_.config_path, options_.overrides);
        if (!result.ok()) {
            for (const auto& line : result.error_lines()) {
                spdlog::error("config: {}", line);
            }
            spdlog::error("config: {} is invalid; keeping the running configuration", options_.config_path);
            notifier_.ready();
            return;
        }
        if (options_.log_level) {
            result.config.log_level = *options_.log_level;  // the command line wins over the file
        }
        const auto changes = diff_config(config_, result.config);
        if (changes.empty()) {
            spdlog::info("config: reloaded {}, nothing changed", options_.config_path);
        }
        for (const auto& c : changes) {
            // Values are cut as in the loader's errors: a long one is not logged whole.
            const auto from = excerpt(c.from, 256), to = excerpt(c.to, 256);
            if (c.runtime) {
                spdlog::info("config: {}: {} -> {} (applied)", c.key, from, to);
            } else {
                spdlog::warn("config: {}: {} -> {} (takes effect after a restart)", c.key, from, to);
            }
        }
        set_log_level(result.config.log_level);
        config_.log_level = result.config.log_level;
        const auto& gl = result.config.groundlink;
        config_.groundlink.telemetry_rates = gl.telemetry_rates;
        config_.groundlink.telemetry_budget_share = gl.telemetry_budget_share;
        config_.groundlink.telemetry_min_hz = gl.telemetry_min_hz;
        bus_.publish(groundlink::TelemetryConfigChanged{telemetry_config(config_)});
        notifier_.ready();
    }

    void do_watchdog() {
        // A service silent for half the period stops the pings, checked every quarter period: a hang is
        // noticed within three quarters of a period, so systemd's watchdog fires at most 1.75 periods after
        // it. Services report progress every quarter period (progress_interval()), twice within the limit.
        const auto period = std::chrono::duration_cast<Duration>(*notifier_.watchdog_period());
        const auto stalled = health_.stalled(SteadyClock::now(), period / 2);
        if (stalled.empty()) {
            notifier_.watchdog();
            watchdog_named_.clear();
        } else if (std::any_of(stalled.begin(), stalled.end(),
                               [this](const std::string& s) { return !watchdog_named_.contains(s); })) {
            // No ping: systemd will restart the daemon if this lasts for the watchdog period. With one
            // service thread every service waits behind the stuck one, and whichever last ticked earliest is
            // the first past the limit; the complaint is repeated as the list grows, at most once per
            // service, so the stuck one is always named.
            spdlog::error("watchdog: not pinging systemd: no progress from {}", fmt::join(stalled, ", "));
            watchdog_named_.insert(stalled.begin(), stalled.end());
        }
        watchdog_timer_.expires_after(period / 4);
        watchdog_timer_.async_wait([this](boost::system::error_code ec) {
            if (!ec) {
                do_watchdog();
            }
        });
    }

    void arm_test_hang() {
#ifdef AIRSEG_TEST_HANG_INJECTION
        // Test-only (build option AIRSEG_TEST_HANG_INJECTION): AIRSEG_TEST_HANG=<service>:<delay ms> blocks
        // that service's strand after the delay, as a deadlock would, to prove the watchdog stops pinging.
        const char* spec = std::getenv("AIRSEG_TEST_HANG");
        if (spec == nullptr) {
            return;
        }
        const std::string text(spec);
        const auto colon = text.find(':');
        const std::string name = text.substr(0, colon);
        const long delay_ms =
            colon == std::string::npos ? 0 : std::strtol(text.c_str() + colon + 1, nullptr, 10);
        for (auto& s : services_) {
            if (s->name() == name) {
                auto timer =
                    std::make_shared<asio::steady_timer>(strand_, std::chrono::milliseconds(delay_ms));
                timer->async_wait([timer, svc = s.get()](boost::system::error_code ec) {
                    if (!ec) {
                        svc->inject_hang();
                    }
                });
            }
        }
#endif
    }

    CliOptions options_;
    Config config_;
    asio::io_context io_;          // the services
    asio::io_context control_io_;  // strand_: signals, the watchdog, systemd
    Strand strand_;
    // The autopilot's status section and the status LED follow the autopilot's status, published five times
    // a second: on the services' thread, they wake no other thread for it.
    Strand adapters_strand_;
    asio::signal_set signals_;
    asio::steady_timer watchdog_timer_;
    SystemdNotifier notifier_;
    Bus bus_;
    HealthRegistry health_;
    CommandDispatcher commands_;
    WakeSharing wakes_;
    ServiceContext context_;
    hal::LibgpiodFactory gpio_;
    std::vector<std::unique_ptr<Service>> services_;
    std::unique_ptr<AutopilotStatusSection> autopilot_section_;
    std::unique_ptr<StatusLedDriver> status_led_;
    std::unique_ptr<AutopilotCommands> autopilot_commands_;
    Subscription line_sub_;
    bool stopping_ = false;
    std::set<std::string> watchdog_named_;  // services already named in this stall's complaints
};

App::App(CliOptions options, Config config)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(config))) {}
App::~App() = default;
int App::run() {
    return impl_->run();
}

}  // namespace airseg::daemon
