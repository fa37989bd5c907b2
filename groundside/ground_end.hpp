#pragma once
// The ground end of the radio link, asynchronous on an asio strand: opens the serial radio port(s) or the UDP
// socket, runs the same ground-link transport core as the vehicle, decodes the ground protocol and reports
// once a second how many pushed telemetry messages arrived (the vehicle measures delivery with it). Used by
// airsegctl on a radio (RadioClient) and by the ground hub, airseg-ground.
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "groundside/reception_report_timing.hpp"
#include "services/common/asio.hpp"
#include "services/groundlink/link/link_driver.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"
#include "services/groundlink/transport/radio_profile.hpp"

namespace airseg::hal {
class SerialPort;
class UdpSocket;
}  // namespace airseg::hal

namespace airseg::groundside {

struct RadioOptions {
    std::vector<std::string> ports;  // --link PATH[,PATH2], in the same pair order as the vehicle's ports
    unsigned baud = 57600;
    std::string mode = "single";  // single | split | redundant (two ports need split or redundant)
    std::string udp;              // HOST:PORT instead of serial ports
    std::string key_file;         // must match the vehicle's groundlink.key_file
    // --radio: the same as the vehicle's groundlink.radio; serial links only
    groundlink::RadioProfile profile;
    bool profile_given = false;  // --radio was given (refused with --udp: there is no radio to describe)
};

/// Checks option combinations; returns a message for people, empty when fine.
std::string validate(const RadioOptions& options);

class GroundEnd {
  public:
    struct Handlers {
        std::function<void(groundlink::protocol::Message)> on_message;
        std::function<void(const groundlink::TransportEvent&)> on_event;
    };

    GroundEnd(Strand strand, RadioOptions options, Handlers handlers);
    ~GroundEnd();
    GroundEnd(const GroundEnd&) = delete;
    GroundEnd& operator=(const GroundEnd&) = delete;

    /// Opens the ports and starts the transport; returns an error for people, empty on success.
    std::string open();
    void stop();

    // On the strand:
    groundlink::SendResult send_safe(std::uint8_t priority, const groundlink::protocol::Message& message);
    groundlink::SendResult send_fast(std::uint8_t priority, std::uint16_t topic,
                                     const groundlink::protocol::Message& message);
    /// The largest message the transport carries whole.
    std::size_t max_message_size() const;

    /// Link statistics as the status document's groundlink section shows them, seen from the ground.
    nlohmann::json link_stats() const;
    bool link_up() const;
    /// Why the vehicle's handshakes cannot be taken, for people ("not authorised: ..."); empty while none
    /// has shown a key mismatch.
    std::string authorisation_problem() const;
    /// Bytes this end's transport wrote to the link so far (all paths, framing included).
    std::uint64_t bytes_sent() const;
    /// Whether the key the vehicle accepted is loaded (an authenticated link).
    bool keyed() const { return keyed_; }

  private:
    void do_report();
    void on_bytes(std::size_t path, std::span<const std::uint8_t> bytes);
    void send_report_if_due(TimePoint now);
    void on_delivered(groundlink::Delivered m);

    Strand strand_;
    RadioOptions options_;
    Handlers handlers_;
    std::unique_ptr<groundlink::LinkDriver> driver_;
    std::vector<std::unique_ptr<hal::SerialPort>> ports_;
    std::unique_ptr<hal::UdpSocket> udp_;
    asio::steady_timer report_timer_;
    std::uint32_t pushed_received_ = 0;
    ReportTiming report_timing_;
    bool keyed_ = false;
    bool stopped_ = false;
};

}  // namespace airseg::groundside
