#include "tools/linksim/link_emulator.hpp"

#include <algorithm>
#include <iostream>
#include <vector>

#include "tools/linksim/control.hpp"

namespace airseg::linksim {

namespace {

// Output is handed to the ptys in batches: waking for every byte at 115200 baud would cost more than it
// shows.
constexpr Duration kMinWake = std::chrono::milliseconds(1);
// While a backlog waits for UART space the model announces no deadline; look again this often.
constexpr Duration kBacklogRetry = std::chrono::milliseconds(2);

}  // namespace

LinkEmulator::LinkEmulator(boost::asio::io_context& io, LinkSimOptions options)
    : options_(std::move(options)),
      strand_(boost::asio::make_strand(io)),
      model_(options_.radio, SteadyClock::now()),
      timer_(strand_),
      stats_timer_(strand_) {
    for (Side s : {Side::A, Side::B}) {
        hal::PtyConfig pc;
        pc.link_path = s == Side::A ? options_.a_path : options_.b_path;
        ptys_[index(s)] = std::make_unique<hal::Pty>(strand_, pc);
    }
}

LinkEmulator::~LinkEmulator() {
    stop();
}

std::string LinkEmulator::start() {
    for (Side s : {Side::A, Side::B}) {
        hal::Pty& p = *ptys_[index(s)];
        if (auto r = p.open(); !r.ok()) {
            return r.message;
        }
        p.on_peer_open([this, s] {
            hosts_[index(s)].peer_connected = true;
            pump();
        });
        p.on_peer_close([this, s] { hosts_[index(s)].peer_connected = false; });
        p.start_reading([this, s](std::span<const std::uint8_t> bytes) { on_bytes(s, bytes); });
    }
    if (!options_.control_path.empty()) {
        control_ = std::make_unique<toolcommon::ControlSocket>(
            strand_, options_.control_path, [this](const std::string& c) { return on_command(c); });
        std::string message;
        if (control_->open(message)) {
            return message;
        }
    }
    schedule_stats();
    return {};
}

void LinkEmulator::stop() {
    if (stopped_) {
        return;
    }
    stopped_ = true;
    timer_.cancel();
    stats_timer_.cancel();
    control_.reset();
}

void LinkEmulator::on_bytes(Side side, std::span<const std::uint8_t> bytes) {
    auto& q = backlog_[index(side)];
    const std::size_t room = options_.host_backlog - std::min(options_.host_backlog, q.size());
    const std::size_t take = std::min(room, bytes.size());
    q.insert(q.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(take));
    hosts_[index(side)].backlog_dropped += bytes.size() - take;
    pump();
}

void LinkEmulator::pump() {
    if (stopped_) {
        return;
    }
    const TimePoint t = now();
    for (Side s : {Side::A, Side::B}) {
        auto& q = backlog_[index(s)];
        if (q.empty()) {
            continue;
        }
        const std::size_t n = std::min(q.size(), model_.serial_space(s, t));
        const std::vector<std::uint8_t> chunk(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(n));
        const std::size_t accepted = model_.push(s, chunk, t);
        q.erase(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(accepted));
    }
    for (Side s : {Side::A, Side::B}) {
        hal::Pty& p = *ptys_[index(s)];
        hosts_[index(s)].peer_connected = p.peer_connected();
        auto out = model_.poll_output(s, t);
        if (out.empty()) {
            continue;
        }
        const std::size_t n = out.size();
        if (!p.peer_connected() || p.write(std::move(out)) != hal::WriteResult::Queued) {
            hosts_[index(s)].not_written += n;
        }
    }
    arm(t);
}

void LinkEmulator::arm(TimePoint t) {
    TimePoint next = model_.poll_timeout();
    if (!backlog_[0].empty() || !backlog_[1].empty()) {
        next = std::min(next, t + kBacklogRetry);
    }
    if (next == kNever) {
        return;  // nothing in flight: the next pty read or command wakes us
    }
    next = std::max(next, t + kMinWake);
    if (armed_ != kNever && armed_ <= next) {
        return;  // an earlier or equal wake-up is already set
    }
    armed_ = next;
    timer_.expires_at(next);
    timer_.async_wait([this](const boost::system::error_code& ec) { on_timer(ec); });
}

void LinkEmulator::on_timer(const boost::system::error_code& ec) {
    if (ec == boost::asio::error::operation_aborted) {
        return;  // re-armed earlier, or stopping
    }
    armed_ = kNever;
    pump();
}

void LinkEmulator::schedule_stats() {
    if (options_.stats_interval <= Duration::zero()) {
        return;
    }
    stats_timer_.expires_after(options_.stats_interval);
    stats_timer_.async_wait([this](const boost::system::error_code& ec) {
        if (ec) {
            return;
        }
        if (options_.json) {
            std::cout << stats_json().dump() << std::endl;
        } else {
            std::cout << stats_text() << std::flush;
        }
        schedule_stats();
    });
}

std::string LinkEmulator::on_command(const std::string& command) {
    if (command == "stats") {
        pump();
        return stats_json().dump();
    }
    if (command == "help") {
        return "ok commands: outage S [ab|ba|both], loss P, ber P, corrupt P, frame-loss P, latency MS, down "
               "a|b, "
               "up a|b, stats";
    }
    std::string reply = apply_control(model_, command, now());
    pump();
    return reply;
}

nlohmann::json LinkEmulator::stats_json() const {
    return linksim::stats_json(model_, hosts_, now());
}

std::string LinkEmulator::stats_text() const {
    return linksim::stats_text(model_, hosts_, now());
}

}  // namespace airseg::linksim
