#include "ground/fleet_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "base/fnv1a.hpp"
#include "services/common/command_record.hpp"

namespace airseg::ground {

nlohmann::json with_request_id(nlohmann::json request, const nlohmann::json& id) {
    if (!request.is_object() || request.contains("request_id")) {
        return request;
    }
    const std::string text = id.is_string()
                                 ? id.get<std::string>()
                                 : id.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    std::string request_id = "mqtt:" + text;
    const bool printable = std::all_of(text.begin(), text.end(), [](char c) { return c > ' ' && c < 0x7f; });
    if (text.empty() || !printable || request_id.size() > CommandRecord::kMaxIdLength) {
        request_id = fmt::format("mqtt:#{:016x}", fnv1a64(text));
    }
    request["request_id"] = std::move(request_id);
    return request;
}

}  // namespace airseg::ground
