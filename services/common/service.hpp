#pragma once
// Base of every long-running service in airsegd. A service owns a strand; everything it does runs there.
// It proves it is alive by a progress tick posted on that same strand: if a handler blocks the strand, the
// tick stops, the watchdog notices, and systemd restarts the daemon.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "base/time.hpp"
#include "services/common/asio.hpp"
#include "services/common/bus.hpp"
#include "services/common/command_dispatcher.hpp"
#include "services/common/health.hpp"
#include "services/common/slack_timer.hpp"
#include "services/common/wake_sharing.hpp"

namespace airseg {

struct ServiceContext {
    asio::io_context& io;
    Bus& bus;
    HealthRegistry& health;
    CommandDispatcher& commands;
    Duration progress_interval = std::chrono::seconds(1);
    /// Where periodic work waits for a wake-up to share (wake_sharing.hpp); null: every tick on its own
    /// timer.
    WakeSharing* wakes = nullptr;
};

class Service {
  public:
    Service(std::string name, ServiceContext& ctx);
    virtual ~Service();
    Service(const Service&) = delete;
    Service& operator=(const Service&) = delete;

    const std::string& name() const { return name_; }
    Strand& strand() { return strand_; }

    /// Starts the service on its strand; `started` runs there once on_start() returned.
    void start(std::function<void()> started = {});
    /// Stops the service on its strand; `stopped` runs there once on_stop() returned.
    void stop(std::function<void()> stopped = {});

    /// Test-only: block this service's strand until stop() is called, as a deadlocked handler would.
    void inject_hang();

  protected:
    virtual void on_start() = 0;
    virtual void on_stop() = 0;
    /// Called on the strand at each progress tick (every ServiceContext::progress_interval, all services on
    /// the same instants): for slow housekeeping that needs no wake-up of its own.
    virtual void on_tick(TimePoint /*now*/) {}

    /// Input arrived (bytes from a port or a socket): periodic work already due runs in this wake-up.
    void woke_for_input() {
        if (ctx_.wakes != nullptr) {
            ctx_.wakes->woke(SteadyClock::now());
        }
    }

    /// Health changes are logged once per change and shown in the status document.
    void set_health(Health health, std::string error = {});

    ServiceContext& ctx_;

  private:
    void do_tick();

    std::string name_;
    Strand strand_;
    SlackTimer tick_timer_;
    bool running_ = false;

    std::mutex hang_mutex_;
    std::condition_variable hang_cv_;
    bool hang_released_ = false;
};

}  // namespace airseg
