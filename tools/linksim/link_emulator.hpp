#pragma once
// airseg-linksim's event loop: two pseudo-terminals (hal::Pty) joined by the radio model, driven in real
// time. Bytes a host writes to its pty wait in a bounded backlog and are fed to the model as fast as the
// modelled UART takes them (a pty cannot make the writer block at the serial rate, so the backlog stands in
// for that); the model's output is written to the other pty; one steady_timer follows the model's
// poll_timeout().
#include <array>
#include <deque>
#include <memory>
#include <string>

#include "hal/asio.hpp"
#include "hal/pty.hpp"
#include "tools/common/control_socket.hpp"
#include "tools/linksim/link_stats.hpp"
#include "tools/linksim/options.hpp"
#include "tools/linksim/radio_model.hpp"

namespace airseg::linksim {

class LinkEmulator {
  public:
    LinkEmulator(boost::asio::io_context& io, LinkSimOptions options);
    ~LinkEmulator();
    LinkEmulator(const LinkEmulator&) = delete;
    LinkEmulator& operator=(const LinkEmulator&) = delete;

    /// Creates both ptys and the control socket. Returns an error message naming the path, or empty.
    std::string start();
    /// Cancels timers and closes the control socket; the ptys go away with the emulator.
    void stop();

    nlohmann::json stats_json() const;
    std::string stats_text() const;
    const hal::Pty& pty(Side side) const { return *ptys_[index(side)]; }

  private:
    void on_bytes(Side side, std::span<const std::uint8_t> bytes);
    void pump();
    void arm(TimePoint now);
    void on_timer(const boost::system::error_code& ec);
    void schedule_stats();
    std::string on_command(const std::string& command);
    TimePoint now() const { return SteadyClock::now(); }

    LinkSimOptions options_;
    hal::Executor strand_;
    RadioModel model_;
    std::array<std::unique_ptr<hal::Pty>, 2> ptys_;
    std::array<std::deque<std::uint8_t>, 2> backlog_;
    std::array<HostStats, 2> hosts_{};
    boost::asio::steady_timer timer_;
    TimePoint armed_ = kNever;
    boost::asio::steady_timer stats_timer_;
    std::unique_ptr<toolcommon::ControlSocket> control_;
    bool stopped_ = false;
};

}  // namespace airseg::linksim
