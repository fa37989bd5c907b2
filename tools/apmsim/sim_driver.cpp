#include "tools/apmsim/sim_driver.hpp"

#include <iostream>

#include "tools/apmsim/control.hpp"

namespace airseg::apmsim {

namespace {

// Waking more often than this costs more than it shows: the core catches up whole physics steps.
constexpr Duration kMinWake = std::chrono::milliseconds(1);
// A wake this late means the simulator itself was not running (stopped, or starved of CPU): the board it
// models fell silent meanwhile, and a peer's link watch may rightly have said so. Logged, so that a link
// loss seen by the peer can be told from one the peer made up.
constexpr Duration kLateWakeLogged = std::chrono::milliseconds(500);
// Bytes queued beside the pty's own buffer (itself some 64 KiB): more than a parameter list's burst and a
// whole kernel buffer behind means the peer is not reading (or is starved), and what it hears is that old.
constexpr std::size_t kBacklogLogged = 64 * 1024;

}  // namespace

SimDriver::SimDriver(boost::asio::io_context& io, ApmSimOptions options)
    : options_(std::move(options)),
      strand_(boost::asio::make_strand(io)),
      real_origin_(SteadyClock::now()),
      timer_(strand_),
      noise_rng_(static_cast<std::uint32_t>(options_.sim.seed * 2654435761U + 7)) {
    RoverSimConfig config = options_.sim;
    config.unix_time_at_start_us = static_cast<std::uint64_t>(
        std::chrono::duration_cast<microseconds>(std::chrono::system_clock::now().time_since_epoch())
            .count());
    // The ground station on the other end runs in real time: the board's mission protocol patience
    // (re-request, give up) is kept in real time too, or a fast speedup would make the board give up on a
    // partner that answers promptly.
    if (options_.speedup > 1.0) {
        config.mission_rerequest =
            std::chrono::duration_cast<Duration>(config.mission_rerequest * options_.speedup);
        config.mission_give_up =
            std::chrono::duration_cast<Duration>(config.mission_give_up * options_.speedup);
    }
    // Simulated time starts equal to the real clock, so both share one origin.
    sim_ = std::make_unique<RoverSim>(config, real_origin_);
    for (const auto& [name, value] : options_.params) {
        sim_->set_param(name, value, real_origin_, "command line");
    }
    sim_->faults() = options_.faults;
    if (options_.reboot_at) {
        sim_->schedule_reboot(real_origin_ + *options_.reboot_at);
    }
    hal::PtyConfig pc;
    pc.link_path = options_.link_path;
    pty_ = std::make_unique<hal::Pty>(strand_, pc);
}

SimDriver::~SimDriver() {
    stop();
}

TimePoint SimDriver::sim_now() const {
    const auto real = SteadyClock::now() - real_origin_;
    return real_origin_ + std::chrono::duration_cast<Duration>(real * options_.speedup);
}

TimePoint SimDriver::to_real(TimePoint sim_time) const {
    if (sim_time == kNever) {
        return kNever;
    }
    return real_origin_ + std::chrono::duration_cast<Duration>((sim_time - real_origin_) / options_.speedup);
}

std::string SimDriver::start() {
    if (auto r = pty_->open(); !r.ok()) {
        return r.message;
    }
    pty_->on_peer_open([this] {
        on_port_opened();
        pump();
    });
    pty_->on_peer_close([this] {
        peer_present_ = false;
        log("port closed");
    });
    pty_->start_reading([this](std::span<const std::uint8_t> bytes) {
        // The open is sampled, so a fast writer's first bytes can arrive before it is seen; on the board the
        // DTR reset comes first and those bytes meet the boot loader.
        on_port_opened();
        if (baud_mismatch()) {
            sim_->handle_bytes(noise(bytes.size()), sim_now());
        } else {
            sim_->handle_bytes(bytes, sim_now());
        }
        pump();
    });
    if (!options_.control_path.empty()) {
        control_ = std::make_unique<toolcommon::ControlSocket>(
            strand_, options_.control_path, [this](const std::string& c) { return on_command(c); });
        std::string message;
        if (control_->open(message)) {
            return message;
        }
    }
    schedule_faults();
    boost::asio::dispatch(strand_, [this] { pump(); });
    return {};
}

void SimDriver::stop() {
    if (stopped_) {
        return;
    }
    stopped_ = true;
    timer_.cancel();
    for (auto& t : fault_timers_) {
        t->cancel();
    }
    control_.reset();
    pty_->unplug();
}

void SimDriver::reboot() {
    boost::asio::dispatch(strand_, [this] {
        log("reboot by signal");
        sim_->reboot(sim_now());
        pump();
    });
}

void SimDriver::pump() {
    if (stopped_) {
        return;
    }
    const TimePoint now = sim_now();
    if (sim_->poll_timeout() <= now) {
        sim_->handle_timeout(now);
    }
    auto bytes = sim_->poll_transmit();
    if (!bytes.empty() && pty_->is_open() && pty_->peer_connected()) {
        pty_->write(baud_mismatch() ? noise(bytes.size()) : std::move(bytes));
        const std::size_t queued = pty_->queued_bytes();
        if (queued > kBacklogLogged && !backlog_logged_) {
            log(std::to_string(queued) + " bytes queued that the port did not take: the peer is not reading");
        }
        backlog_logged_ = queued > kBacklogLogged || (backlog_logged_ && queued > 0);
    }
    log_new_events();
    arm();
}

void SimDriver::arm() {
    const TimePoint next_sim = sim_->poll_timeout();
    if (next_sim == kNever) {
        return;
    }
    const TimePoint next = std::max(to_real(next_sim), SteadyClock::now() + kMinWake);
    if (armed_ != kNever && armed_ <= next) {
        return;  // an earlier or equal wake-up is already set
    }
    armed_ = next;
    timer_.expires_at(next);
    timer_.async_wait([this](const boost::system::error_code& ec) {
        if (ec == boost::asio::error::operation_aborted) {
            return;  // re-armed earlier, or stopping
        }
        if (const Duration late = SteadyClock::now() - armed_; late > kLateWakeLogged) {
            log("woke " +
                std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(late).count()) +
                " ms late: the simulator was not running, and the board sent nothing meanwhile");
        }
        armed_ = kNever;
        pump();
    });
}

void SimDriver::at_sim_time(Duration after_start, std::function<void()> action) {
    auto t = std::make_unique<boost::asio::steady_timer>(strand_);
    t->expires_at(to_real(real_origin_ + after_start));
    t->async_wait([this, action = std::move(action)](const boost::system::error_code& ec) {
        if (!ec && !stopped_) {
            action();
            pump();
        }
    });
    fault_timers_.push_back(std::move(t));
}

void SimDriver::schedule_faults() {
    for (const auto& w : options_.hb_stalls) {
        at_sim_time(w.start, [this, w] { sim_->stall_heartbeats(w.length, sim_now()); });
    }
    for (const auto& w : options_.unplugs) {
        at_sim_time(w.start, [this] { log(unplug()); });
        at_sim_time(w.start + w.length, [this] { log(replug()); });
    }
}

// Two UARTs at different rates do not exchange bytes, they exchange framing errors: what each side receives
// is noise. The pty carries bytes at any rate, so the rate the peer set on its end decides.
bool SimDriver::baud_mismatch() {
    if (options_.baud == 0) {
        return false;
    }
    const unsigned peer = pty_->peer_baud();
    const bool mismatch = peer != 0 && peer != options_.baud;
    if (mismatch && peer != mismatch_logged_) {
        log("peer at " + std::to_string(peer) + " baud, board at " + std::to_string(options_.baud) +
            ": both sides hear noise");
    } else if (!mismatch && mismatch_logged_ != 0) {
        log("peer at " + std::to_string(options_.baud) + " baud, as the board");
    }
    mismatch_logged_ = mismatch ? peer : 0;
    return mismatch;
}

std::vector<std::uint8_t> SimDriver::noise(std::size_t n) {
    std::vector<std::uint8_t> out(n);
    for (auto& b : out) {
        b = static_cast<std::uint8_t>(noise_rng_() >> 24);
    }
    return out;
}

void SimDriver::on_port_opened() {
    if (peer_present_) {
        return;
    }
    peer_present_ = true;
    log("port opened" + std::string(options_.sim.reset_on_open ? ": rebooting" : ""));
    sim_->port_opened(sim_now());
}

std::string SimDriver::unplug() {
    if (!pty_->is_open()) {
        return "error: unplug: already unplugged";
    }
    pty_->unplug();
    peer_present_ = false;
    return "ok unplugged " + options_.link_path;
}

std::string SimDriver::replug() {
    if (pty_->is_open()) {
        return "error: replug: still plugged in";
    }
    if (auto r = pty_->replug(); !r.ok()) {
        return "error: replug: " + r.message;
    }
    return "ok replugged " + options_.link_path + " -> " + pty_->slave_path();
}

std::string SimDriver::on_command(const std::string& command) {
    const TimePoint now = sim_now();
    if (sim_->poll_timeout() <= now) {
        sim_->handle_timeout(now);  // the answer describes the present
    }
    std::string reply = apply_control(*sim_, command, now,
                                      LinkControl{[this] { return unplug(); }, [this] { return replug(); }});
    if (command.rfind("state", 0) != 0 && command.rfind("modes", 0) != 0 && command.rfind("stats", 0) != 0) {
        log("control: " + command + " -> " + reply);
    }
    pump();
    return reply;
}

void SimDriver::log(const std::string& line) const {
    if (!options_.quiet) {
        const double t = std::chrono::duration<double>(sim_now() - real_origin_).count();
        std::cerr << "airseg-apmsim[" << options_.link_path << "] t=" << t << ": " << line << std::endl;
    }
}

void SimDriver::log_new_events() {
    const auto& modes = sim_->mode_history();
    for (; modes_logged_ < modes.size(); ++modes_logged_) {
        const ModeChange& m = modes[modes_logged_];
        log(std::string("mode ") + std::string(mode_name(m.from)) + " -> " + std::string(mode_name(m.to)) +
            " (" + m.cause + ")");
    }
    const auto& reached = sim_->reached();
    reached_logged_ = std::min(reached_logged_, reached.size());  // the log is bounded and may drop old ones
    for (; reached_logged_ < reached.size(); ++reached_logged_) {
        log("reached item " + std::to_string(reached[reached_logged_].seq));
    }
}

}  // namespace airseg::apmsim
