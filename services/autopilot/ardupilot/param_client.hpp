#pragma once
// ParamClient: the autopilot's parameter table, sans-IO.
//
// fetch_all() downloads the table (PARAM_REQUEST_LIST; when the stream goes quiet, the missing indices are
// asked for one by one with PARAM_REQUEST_READ, in rounds, until all are in or param_list_timeout passes).
// get() reads one parameter; set() writes one and checks the echo: the autopilot's PARAM_VALUE must carry
// the value written, else the write is retried and finally reported Refused with the value read back.
// Operations run one at a time, in order; each ends with exactly one ParamCompletion.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/ardupilot/outbox.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::autopilot::ardupilot {

struct ParamEntry {
    float value = 0.0f;
    std::uint8_t type = 9;  // MAV_PARAM_TYPE
    std::uint16_t index = 0;
};

struct ParamCompletion {
    std::uint32_t id = 0;
    enum class Kind : std::uint8_t { FetchAll, Get, Set } kind = Kind::Get;
    RequestResult result = RequestResult::Ok;
    std::string name;
    std::optional<float> value;  // Get/Set: the value the autopilot reported
    std::string detail;
};

struct ParamClientConfig {
    Duration timeout = seconds(1);         // per attempt of a get/set, and the quiet gap of a fetch
    unsigned retries = 3;                  // per get/set, and per fetch round without progress
    Duration fetch_timeout = seconds(60);  // a whole fetch
};

class ParamClient {
  public:
    static constexpr std::size_t kMaxQueued = 64;
    /// The most parameters a table may announce (PARAM_COUNT) and the cache may hold: ArduPilot boards have
    /// about 1,000 to 1,300. The cache holds at most the count announced (this many before any), and a new
    /// table (another count) replaces the old one; names beyond it are dropped and counted (dropped()).
    static constexpr std::size_t kMaxParams = 4096;
    static constexpr std::size_t kReadsPerRound = 8;  // individual reads in flight while filling gaps

    ParamClient(Outbox& outbox, std::uint8_t target_sysid, std::uint8_t target_compid,
                ParamClientConfig config);

    std::uint32_t fetch_all(TimePoint now);
    std::uint32_t get(const std::string& name, TimePoint now);
    std::uint32_t set(const std::string& name, float value, TimePoint now);
    void cancel_all(const std::string& why);

    bool handle_frame(const mavlink::Frame& frame, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    std::optional<ParamCompletion> poll_completion();

    const std::map<std::string, ParamEntry>& table() const { return table_; }
    std::optional<float> cached(const std::string& name) const;
    /// Parameters announced by the autopilot (param_count), 0 before any PARAM_VALUE.
    std::size_t announced() const { return announced_; }
    std::uint64_t retransmissions() const { return retransmissions_; }
    /// PARAM_VALUEs not cached: a new name past the announced count, or a name that is not printable ASCII.
    std::uint64_t dropped() const { return dropped_; }

  private:
    struct Op {
        std::uint32_t id = 0;
        ParamCompletion::Kind kind = ParamCompletion::Kind::Get;
        std::string name;
        float value = 0.0f;
        unsigned attempt = 0;
        TimePoint deadline = kNever;
        TimePoint give_up = kNever;  // fetch only
        bool started = false;
        std::optional<float> last_echo;
    };

    std::uint32_t enqueue(Op op, TimePoint now);
    void start_front(TimePoint now);
    void send_for(Op& op, TimePoint now);
    void request_missing(TimePoint now);
    void finish(RequestResult r, std::optional<float> value, std::string detail, TimePoint now);
    bool fetch_complete() const;
    static bool same_value(float a, float b, std::uint8_t type);

    Outbox& out_;
    std::uint8_t target_sysid_;
    std::uint8_t target_compid_;
    ParamClientConfig config_;
    std::deque<Op> ops_;
    std::deque<ParamCompletion> done_;
    std::uint32_t next_id_ = 1;
    std::map<std::string, ParamEntry> table_;
    std::vector<bool> have_index_;
    std::size_t announced_ = 0;
    std::size_t have_count_ = 0;
    std::uint64_t retransmissions_ = 0;
    std::uint64_t dropped_ = 0;
};

}  // namespace airseg::autopilot::ardupilot
