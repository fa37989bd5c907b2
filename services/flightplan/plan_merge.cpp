#include "services/flightplan/plan_merge.hpp"

#include <yaml-cpp/yaml.h>

namespace airseg::flightplan {

namespace {

void append_list(YAML::Node into, const YAML::Node& from) {
    if (!from.IsSequence())
        return;
    for (const auto& item : from)
        into.push_back(YAML::Clone(item));
}

}  // namespace

MergedPlan append_plan_text(std::string_view running, std::string_view appended) {
    MergedPlan out;
    try {
        YAML::Node base = YAML::Load(std::string(running));
        const YAML::Node extra = YAML::Load(std::string(appended));
        YAML::Node plan = base["plan"];
        const YAML::Node more = extra["plan"];
        if (!plan.IsMap() || !more.IsMap()) {
            out.error = "both plans need a 'plan' mapping";
            return out;
        }
        for (const char* key : {"elements", "blocks", "no_fly"}) {
            if (!more[key].IsDefined() || more[key].IsNull())
                continue;
            if (!plan[key].IsDefined() || plan[key].IsNull())
                plan[key] = YAML::Node(YAML::NodeType::Sequence);
            YAML::Node list = plan[key];
            append_list(list, more[key]);
        }
        YAML::Emitter emitter;
        emitter << base;
        if (!emitter.good()) {
            out.error = "cannot write the merged plan: " + emitter.GetLastError();
            return out;
        }
        out.text = std::string(emitter.c_str()) + "\n";
    } catch (const YAML::Exception& e) {
        out.error = std::string("cannot merge the plans: ") + e.what();
    }
    return out;
}

}  // namespace airseg::flightplan
