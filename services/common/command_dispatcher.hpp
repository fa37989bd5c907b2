#pragma once
// One command dispatcher for every way a command reaches the vehicle: the local socket on the board today,
// the ground link later. A command is a JSON object {"cmd": "<name>", ...arguments}; its handler runs on the
// strand of the service that registered it and must call the reply exactly once.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "services/common/asio.hpp"

namespace airseg {
class CommandRecord;
struct CommandRecordStats;
}  // namespace airseg

namespace airseg {

using Json = nlohmann::json;

/// Who is asking. A monitor may watch; only control may change anything.
enum class Role { Monitor, Control };

const char* to_string(Role r);

enum class CommandStatus { Ok, Refused, BadRequest, UnknownCommand, Forbidden, Failed };

const char* to_string(CommandStatus s);

struct CommandResult {
    CommandStatus status = CommandStatus::Ok;
    Json result = Json::object();  // command-specific payload when ok
    std::string error;             // what went wrong, for people, when not ok
    bool replayed = false;         // the answer of an earlier run of the same request (command_record.hpp)

    static CommandResult ok(Json result = Json::object()) {
        return {CommandStatus::Ok, std::move(result), {}};
    }
    static CommandResult fail(CommandStatus s, std::string error) {
        return {s, Json::object(), std::move(error)};
    }

    /// The wire form: {"ok":true,"result":{...}} or {"ok":false,"status":"refused","error":"..."}, with
    /// "replayed": true when the answer comes from the record of an earlier run.
    Json to_json() const;
};

class CommandDispatcher {
  public:
    using Reply = std::function<void(CommandResult)>;
    using Handler = std::function<void(const Json& request, Reply reply)>;

    /// Registers `name`; its handler runs on `strand`. `required` is the least role allowed to call it.
    void add(const std::string& name, Strand strand, Role required, Handler handler);

    /// Runs one request. `reply` is called exactly once, from the handler's strand or, for requests that
    /// never reach a handler (malformed, unknown, forbidden), from the caller's context before dispatch
    /// returns.
    void dispatch(const Json& request, Role caller, Reply reply) const;

    std::vector<std::string> names() const;

    /// The record behind "request_id" (command_record.hpp): how often it spared a second run.
    CommandRecordStats record_stats() const;

    CommandDispatcher();
    ~CommandDispatcher();

  private:
    struct Entry {
        Strand strand;
        Role required;
        Handler handler;
    };
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<const Entry>> entries_;
    std::shared_ptr<CommandRecord> record_;  // shared with the replies that finish its entries
};

}  // namespace airseg
