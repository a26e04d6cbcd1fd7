/// @file   StudyMetrics.h
/// @brief  Error metrics with known answers, measured on a running simulation for `ghostfx study`.
/// @details A metric watches one medium (the liquid or the gas) at t = 0 and after every frame,
///          and reports named values at the end. Some metrics also keep a per-frame trace (the
///          surge front, the plume top) that the study compares with a reference run's trace.
///          Definitions, units and where each reference answer comes from are in
///          docs/study.md; the short form is in the comment of each factory below.
#pragma once

#include "Simulation.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace cmd {

/// One look at the simulation: the medium a metric watches, at time `time` (s).
struct MetricSample
{
    const OutputMedium* medium = nullptr;
    double time = 0;
    int frame = 0;     ///< frames advanced (0: the initial state)
    int lastFrame = 0; ///< the frame the run ends with
};

class Metric
{
public:
    /// `name` as written in a study file ("density_error"); `medium` "liquid" or "gas".
    explicit Metric(std::string name, std::string medium = "liquid")
        : mName(std::move(name))
        , mMedium(std::move(medium))
    {}
    virtual ~Metric() = default;
    /// The metric's name as written in a study file ("density_error").
    const std::string& name() const { return mName; }
    /// "liquid" or "gas": the medium it watches.
    const std::string& medium() const { return mMedium; }
    /// The initial state (before the first step).
    virtual void start(const MetricSample&) {}
    /// After every frame.
    virtual void frame(const MetricSample& sample) = 0;
    /// The measured values, as (column, value).
    virtual std::vector<std::pair<std::string, double>> values() const = 0;
    /// A per-frame trace to compare with a reference run (empty if the metric has none).
    virtual std::vector<double> trace() const { return {}; }

private:
    std::string mName, mMedium;
};

/// Settings of one metric in a study file: its name and its options (a JSON object).
struct MetricSpec
{
    std::string name;
    nlohmann::json options = nlohmann::json::object();
};

/// Names of every metric, in documentation order.
const std::vector<std::string>& metricNames();

/// The column a study plots for a metric by default (its main error).
std::string primaryErrorColumn(const std::string& metric, bool haveReference);

/// Make a metric; throws ValueError for an unknown name or a bad option (the message names the
/// option and the value; `where` is the study key, e.g. "study 'tank.json': metrics[1]").
std::unique_ptr<Metric> makeMetric(const MetricSpec& spec, const std::string& where);

/// Compare a trace with the reference run's: rms over the frames both have of (q - q_ref), in
/// the trace's unit, and the same divided by the reference's largest excursion from its start
/// (so 0.05 means "5 % of how far the front or the plume travelled").
struct TraceError
{
    double rms = 0;
    double relative = 0;
};
TraceError compareTraces(const std::vector<double>& trace, const std::vector<double>& reference);

} // namespace cmd
} // namespace ghostfx
