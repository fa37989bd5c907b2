#include "services/common/command_dispatcher.hpp"

#include <atomic>

#include "base/fnv1a.hpp"
#include "base/utf8.hpp"
#include "services/common/command_record.hpp"

namespace airseg {

namespace {

/// Where in `value` the first text (a string or a key) that is not UTF-8 is, as a JSON pointer; nullopt when
/// there is none.
std::optional<std::string> invalid_text(const Json& value, const std::string& at = "") {
    if (value.is_string()) {
        return valid_utf8(value.get_ref<const std::string&>()) ? std::nullopt
                                                               : std::optional(at.empty() ? "/" : at);
    }
    if (value.is_object()) {
        for (const auto& [key, item] : value.items()) {
            if (!valid_utf8(key)) {
                return at + "/" + key;
            }
            if (auto found = invalid_text(item, at + "/" + key)) {
                return found;
            }
        }
    } else if (value.is_array()) {
        for (std::size_t i = 0; i < value.size(); ++i) {
            if (auto found = invalid_text(value[i], at + "/" + std::to_string(i))) {
                return found;
            }
        }
    }
    return std::nullopt;
}

}  // namespace

const char* to_string(Role r) {
    return r == Role::Control ? "control" : "monitor";
}

const char* to_string(CommandStatus s) {
    switch (s) {
        case CommandStatus::Ok:
            return "ok";
        case CommandStatus::Refused:
            return "refused";
        case CommandStatus::BadRequest:
            return "bad_request";
        case CommandStatus::UnknownCommand:
            return "unknown_command";
        case CommandStatus::Forbidden:
            return "forbidden";
        case CommandStatus::Failed:
            return "failed";
    }
    return "failed";
}

Json CommandResult::to_json() const {
    Json out = status == CommandStatus::Ok
                   ? Json{{"ok", true}, {"result", result}}
                   : Json{{"ok", false}, {"status", to_string(status)}, {"error", error}};
    if (replayed) {
        out["replayed"] = true;
    }
    return out;
}

CommandDispatcher::CommandDispatcher() : record_(std::make_shared<CommandRecord>()) {}
CommandDispatcher::~CommandDispatcher() = default;

CommandRecordStats CommandDispatcher::record_stats() const {
    return record_->stats();
}

void CommandDispatcher::add(const std::string& name, Strand strand, Role required, Handler handler) {
    std::lock_guard lock(mutex_);
    entries_[name] = std::make_shared<const Entry>(Entry{std::move(strand), required, std::move(handler)});
}

void CommandDispatcher::dispatch(const Json& request, Role caller, Reply reply) const {
    if (!request.is_object() || !request.contains("cmd") || !request["cmd"].is_string()) {
        reply(CommandResult::fail(CommandStatus::BadRequest,
                                  "request must be a JSON object with a string \"cmd\""));
        return;
    }
    // The radio's CBOR does not check its texts as JSON's parser does; a text kept from a request (a plan's
    // source, a name) would make every later dump of the status document throw.
    if (const auto where = invalid_text(request)) {
        reply(CommandResult::fail(CommandStatus::BadRequest,
                                  "request text is not valid UTF-8 (at " + excerpt(*where) + ")"));
        return;
    }
    const auto name = request["cmd"].get<std::string>();
    std::shared_ptr<const Entry> entry;
    {
        std::lock_guard lock(mutex_);
        auto it = entries_.find(name);
        if (it != entries_.end()) {
            entry = it->second;
        }
    }
    if (!entry) {
        reply(CommandResult::fail(CommandStatus::UnknownCommand, "unknown command '" + excerpt(name) + "'"));
        return;
    }
    if (entry->required == Role::Control && caller != Role::Control) {
        reply(CommandResult::fail(CommandStatus::Forbidden,
                                  "'" + name + "' needs the control role; this connection is a monitor"));
        return;
    }
    // At most once: a command that changes something, sent again under its request id, is answered from
    // the record instead of running twice. Read-only commands (a monitor may call them) run every time.
    if (entry->required == Role::Control) {
        const auto id = CommandRecord::id_of(request);
        if (!id.error.empty()) {
            reply(CommandResult::fail(CommandStatus::BadRequest, id.error));
            return;
        }
        if (id.id) {
            auto content = request;
            content.erase("request_id");
            const auto fingerprint = fnv1a64(content.dump(-1, ' ', false, Json::error_handler_t::replace));
            switch (record_->admit(*id.id, fingerprint, SteadyClock::now(), reply)) {
                case CommandRecord::Admit::Replayed:
                case CommandRecord::Admit::Joined:
                    return;
                case CommandRecord::Admit::Conflict:
                    reply(CommandResult::fail(
                        CommandStatus::BadRequest,
                        "request_id '" + *id.id +
                            "' was used for a different command in the last 10 minutes; a new command "
                            "needs a new id"));
                    return;
                case CommandRecord::Admit::Run:
                    reply = [record = record_, key = *id.id, fingerprint,
                             reply = std::move(reply)](CommandResult r) {
                        record->finish(key, fingerprint, r, SteadyClock::now());
                        reply(std::move(r));
                    };
                    break;
            }
        }
    }
    // Guard the exactly-once promise: a handler bug must not answer twice on a connection.
    auto answered = std::make_shared<std::atomic<bool>>(false);
    Reply once = [answered, reply = std::move(reply)](CommandResult r) {
        if (!answered->exchange(true)) {
            reply(std::move(r));
        }
    };
    asio::post(entry->strand, [entry, request, once] {
        try {
            entry->handler(request, once);
        } catch (const std::exception& e) {
            once(CommandResult::fail(CommandStatus::BadRequest, e.what()));
        }
    });
}

std::vector<std::string> CommandDispatcher::names() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [name, entry] : entries_) {
        out.push_back(name);
    }
    return out;
}

}  // namespace airseg
