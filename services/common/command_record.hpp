#pragma once
// The vehicle's record of recent commands, so that a command is done at most once however often it is sent.
// A client that may send a command again (its answer lost on the radio, a reconnect, the operator running
// airsegctl again with --request-id) names it with "request_id". A command that changes something and carries
// an id already recorded with the same content is not run again: it is answered from the record, or, while
// the first is still running, with the first's answer when it comes. Read-only commands run every time.
// Bounded by entries and age (docs/ground-protocol.md, "At most once").
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/common/command_dispatcher.hpp"

namespace airseg {

struct CommandRecordStats {
    std::uint64_t recorded = 0;         // commands run under a request id
    std::uint64_t replayed = 0;         // answered from the record, not run again
    std::uint64_t joined = 0;           // sent again while the first was running; given the first's answer
    std::uint64_t conflicts = 0;        // an id recorded for a different command: refused
    std::uint64_t forgotten_early = 0;  // entries dropped by the bound before their age
    std::uint64_t unrecorded = 0;       // run without a record: every entry was a command still running
    std::size_t entries = 0;
};

class CommandRecord {
  public:
    using Reply = std::function<void(CommandResult)>;
    static constexpr std::size_t kDefaultEntries = 256;
    static constexpr Duration kDefaultKeep = std::chrono::minutes(10);
    static constexpr std::size_t kMaxIdLength = 64;

    explicit CommandRecord(std::size_t entries = kDefaultEntries, Duration keep = kDefaultKeep);

    /// What a request's "request_id" says: nullopt without one, or the id; `error` set when it is not an id
    /// (a string of 1 to 64 printable ASCII characters, or an unsigned integer).
    struct Id {
        std::optional<std::string> id;
        std::string error;
    };
    static Id id_of(const Json& request);

    enum class Admit { Run, Replayed, Joined, Conflict };
    /// Admits command `id` with content fingerprint `fingerprint`. Run: the caller runs it and calls
    /// finish(). Replayed: `reply` was called with the recorded answer. Joined: `reply` is called with the
    /// answer of the run in progress. Conflict: nothing was called; the id names another command.
    Admit admit(const std::string& id, std::uint64_t fingerprint, TimePoint now, const Reply& reply);
    /// The answer of a command admitted with Run: recorded, and given to every request that joined it.
    void finish(const std::string& id, std::uint64_t fingerprint, const CommandResult& result, TimePoint now);

    CommandRecordStats stats() const;

  private:
    struct Entry {
        std::uint64_t fingerprint = 0;
        TimePoint at{};
        std::optional<CommandResult> result;  // nullopt while running
        std::vector<Reply> waiting;
    };
    void forget_old(TimePoint now);

    const std::size_t max_entries_;
    const Duration keep_;
    mutable std::mutex mutex_;
    std::map<std::string, Entry> entries_;
    std::deque<std::string> order_;  // ids, oldest first
    CommandRecordStats stats_;
};

}  // namespace airseg
