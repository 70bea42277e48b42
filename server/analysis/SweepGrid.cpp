#include "analysis/SweepGrid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Error.h"

namespace gis {

nlohmann::json defaultParams(const ParamTable& table) {
    return ParamSet(table).toJson();
}

namespace {

double numeric(const nlohmann::json& v) {
    return v.is_number() ? v.get<double>() : 0.0;
}

std::string valueText(const nlohmann::json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number_float()) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
        return buf;
    }
    return v.dump();
}

} // namespace

std::vector<GridPoint> oneAtATimeGrid(const ParamTable& table, int steps,
                                      const std::vector<std::string>& knobs) {
    for (const auto& k : knobs)
        if (!table.find(k)) throw InputError("--knobs", "unknown parameter '" + k + "'");
    const nlohmann::json defaults = defaultParams(table);
    std::vector<GridPoint> out;
    out.push_back({"", nullptr, 0, defaults});
    for (const auto& spec : table.specs()) {
        if (!knobs.empty() && std::find(knobs.begin(), knobs.end(), spec.name) == knobs.end()) continue;
        const nlohmann::json& def = defaults[spec.name];
        ParamSet check(table);
        std::vector<GridPoint> above, below, unordered;
        for (const auto& raw : ParamTable::sweepValues(spec, steps)) {
            check.set(spec.name, raw, "sweep"); // the table's own validation and rounding
            nlohmann::json v = check.toJson()[spec.name];
            if (v == def) continue;
            GridPoint p{spec.name, v, 0, defaults};
            p.params[spec.name] = v;
            if (spec.type == ParamType::Int || spec.type == ParamType::Float) {
                p.side = numeric(v) > numeric(def) ? 1 : -1;
                (p.side > 0 ? above : below).push_back(std::move(p));
            } else {
                unordered.push_back(std::move(p));
            }
        }
        std::reverse(below.begin(), below.end());
        for (auto* group : {&above, &below, &unordered})
            for (auto& p : *group)
                if (std::none_of(out.begin(), out.end(),
                                 [&](const GridPoint& q) { return q.params == p.params; }))
                    out.push_back(std::move(p));
    }
    return out;
}

std::string describeChanges(const ParamTable& table, const nlohmann::json& params) {
    const nlohmann::json defaults = defaultParams(table);
    std::string out;
    for (const auto& spec : table.specs()) {
        if (!params.contains(spec.name) || params[spec.name] == defaults[spec.name]) continue;
        out += (out.empty() ? "" : " ") + spec.name + "=" + valueText(params[spec.name]);
    }
    return out.empty() ? "defaults" : out;
}

} // namespace gis
