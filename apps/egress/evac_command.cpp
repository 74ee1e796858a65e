// `egress evac study SCENARIO.yaml --trials N --out DIR`: what the robot buys an evacuation.
// Each trial (seed) runs under three conditions on the same seed: no robot (it is parked off the
// scene; residents open doors themselves where they can), the robot on the scenario's mission
// (escorting), and every door propped open from the start (the upper bound). A trial ends when
// every evacuee is out (at the assembly point beyond the exit) or at the time limit. Printed: a
// table per condition (evacuation time median with its 95 % interval, people left behind,
// robot-resident contacts and closest approach, time the robot was in a doorway with a resident
// within 2 m, and the part of it the robot stood there), per-door flow, queue time and how often
// residents and the robot opened it, and for the
// robot and the propped doors the paired difference from no robot on the same seeds (median with
// its 95 % interval, seeds faster and slower: what the condition buys, with the seeds' own spread
// taken out); written: DIR/study.json, DIR/trials.csv, DIR/evacuated.png (people out vs time,
// median and 10-90 % band per condition).
//
// A trial is a pure function of the scenario file, the condition and the seed, whatever --jobs.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "brain_trial.h"
#include "commands.h"
#include "crowd_rate_options.h"
#include "doorway_judge.h"
#include "egress/hsr_interface/error.h"
#include "egress/perception/image_io.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_model.h"
#include "egress/twin/twin_robot.h"
#include "egress/twin/twin_run.h"
#include "study_stats.h"
#include "workers.h"

namespace egress::apps {
namespace {

constexpr const char* kConditions[] = {"no_robot", "robot", "propped_open"};
// Evacuation times this close under two conditions count as a tie: the same evacuation, seen a
// control period or so apart [s].
constexpr double kTieSec = 0.15;

struct StudyOptions {
  std::string scenario;
  int trials{20};
  int jobs{2};
  std::uint64_t seed_base{1};
  std::string out{"study"};
  std::vector<std::string> conditions{std::begin(kConditions), std::end(kConditions)};
  bool overwrite{false};
  bool quiet{false};
  CrowdRateOptions crowd;
};

bool IsEvacuee(const twin::PersonState& p) {
  return p.behavior == twin::PersonBehavior::kEvacuate;
}

// The scenario as `condition` runs it (defaults of the building already applied).
twin::Scenario ConditionScenario(const twin::Scenario& base, const twin::WorldDescription& world,
                                 const std::string& condition) {
  twin::Scenario s = base;
  if (condition == "robot") return s;
  s.mission.reset();
  s.start_place.clear();
  s.robot_off_scene = true;
  s.robot_start = twin::OffScenePose(world);
  s.success.clear();
  if (condition == "propped_open") {
    for (auto& door : s.doors) {
      door.open_at = {0.0};
      door.timing.hold_open_s = 1e9;
    }
  }
  return s;
}

// Each door's frame with its name.
struct DoorLine : twin::DoorwayFrame {
  std::string name;
};

std::vector<DoorLine> DoorLines(const twin::TwinWorld& world) {
  std::vector<DoorLine> lines;
  for (std::size_t i = 0; i < world.door_count(); ++i)
    lines.push_back({twin::CalcDoorwayFrame(world.door(i)), world.door(i).name});
  return lines;
}

// One trial of one condition.
nlohmann::json RunStudyTrial(const twin::Scenario& scenario, const twin::WorldDescription& world,
                             const std::shared_ptr<const RobotModel>& hsr,
                             const twin::TwinConfig& twin_config, const std::string& condition,
                             std::uint64_t seed) {
  auto model = std::make_shared<const twin::TwinModel>(scenario, world, hsr, twin_config);
  twin::TwinWorld twin_world(model, seed);
  twin::TwinRobot robot(&twin_world);
  behavior::ExecutiveConfig config;
  std::unique_ptr<behavior::Executive> brain;
  if (condition == "robot")
    brain = MakeScenarioExecutive(model->scenario(), model->world(), twin_world, hsr, config);
  const std::vector<DoorLine> lines = DoorLines(twin_world);
  std::map<std::string, std::vector<double>> crossings;  // per door
  std::map<std::string, double> queue;                   // per door: person-seconds waiting
  std::map<std::pair<std::string, std::string>, double> last_side;
  std::vector<twin::DoorwayFrame> doorways(lines.begin(), lines.end());
  DoorwayBlockJudge doorway_judge(std::move(doorways));
  std::vector<Eigen::Vector2d> p_WR;  // the residents still in the building
  // Since when each resident waiting for a door has waited there (for who is left behind).
  std::map<std::string, double> waiting_since;
  const double period = brain ? 1.0 / config.control_rate_hz : 0.1;
  double last_t = 0.0;
  // How far the brain's belief of its base strayed from the truth (M is W in the twin): drift in
  // a crowd or along a corridor shows here before it leaves anyone behind.
  double localization_error_max = 0.0;
  const auto all_out = [&] {
    bool any = false;
    for (const auto& p : twin_world.people()) {
      if (!IsEvacuee(p)) continue;
      any = true;
      if (!p.out) return false;
    }
    return any;
  };
  twin::RunOptions run;
  run.record_trace = false;
  run.control_period = period;
  const twin::RunResult result = twin::RunScenario(
      robot,
      [&](RobotPort& port) {
        if (brain) {
          brain->Step(port);
          localization_error_max = std::max(
              localization_error_max,
              (brain->belief().X_MB.translation() - twin_world.robot_pose().translation()).norm());
        }
        const double t = twin_world.time(), dt = t - last_t;
        last_t = t;
        const Eigen::Vector2d p_WB = twin_world.robot_pose().translation();
        p_WR.clear();
        for (const auto& p : twin_world.people()) {
          if (!IsEvacuee(p) || !p.started || p.out) continue;
          p_WR.push_back(p.position);
          for (const auto& l : lines) {
            const Eigen::Vector2d rel = p.position - l.centre;
            const double side = rel.dot(l.normal);
            auto& last = last_side[{p.name, l.name}];
            if (last != 0.0 && (last < 0) != (side < 0) &&
                std::abs(rel.dot(l.along)) <= l.half_width + 0.1)
              crossings[l.name].push_back(t);
            last = side;
          }
          // Their wait is the door's they wait for (not the nearest one's: in a ward beside
          // another room, the nearest door may be one they never use).
          if (p.phase == twin::PersonPhase::kWaitingForDoor && !p.waiting_for.empty())
            queue[p.waiting_for] += dt;
          if (p.phase == twin::PersonPhase::kWaitingForDoor)
            waiting_since.try_emplace(p.name, t);
          else
            waiting_since.erase(p.name);
        }
        const Twist2 V_B = twin_world.robot_velocity();
        doorway_judge.Step(dt, p_WB, std::hypot(V_B.vx, V_B.vy), p_WR);
        return !all_out();
      },
      run);
  std::vector<double> arrivals;
  int residents = 0, left = 0;
  // Who is left behind, and where: the seeds worth a look say which door kept whom.
  nlohmann::json left_people = nlohmann::json::array();
  for (const auto& p : twin_world.people()) {
    if (!IsEvacuee(p)) continue;
    ++residents;
    if (p.out) {
      arrivals.push_back(p.arrived_at);
    } else {
      ++left;
      const auto since = waiting_since.find(p.name);
      left_people.push_back(
          {{"name", p.name},
           {"mobility", p.mobility},
           {"can_operate", p.can_operate},
           {"phase", std::string(twin::ToString(p.phase))},
           {"waiting_for", p.waiting_for},
           {"waiting_since_s", since != waiting_since.end() && !p.waiting_for.empty()
                                   ? nlohmann::json(since->second)
                                   : nlohmann::json(nullptr)},
           {"position", {p.position.x(), p.position.y()}}});
    }
  }
  std::sort(arrivals.begin(), arrivals.end());
  // Who opened each door, and how often: a resident at its actuator, or the robot (a press or a
  // wave). A door the robot keeps open is one the residents need not operate.
  std::map<std::string, int> by_residents, by_robot;
  for (const twin::TwinEvent& e : twin_world.events()) {
    if (e.kind == "door_operated") ++by_residents[e.subject];
    if (e.kind == "button_pressed") ++by_robot[e.subject];
  }
  int resident_operations = 0, robot_operations = 0;
  nlohmann::json doors = nlohmann::json::object();
  for (const auto& l : lines) {
    const auto& c = crossings[l.name];
    resident_operations += by_residents[l.name];
    robot_operations += by_robot[l.name];
    if (c.empty() && queue[l.name] == 0.0 && by_residents[l.name] == 0 && by_robot[l.name] == 0)
      continue;
    doors[l.name] = {{"crossings", c.size()},
                     {"operated_by_residents", by_residents[l.name]},
                     {"operated_by_robot", by_robot[l.name]},
                     // A rate needs two crossings: one resident through is no flow of 0.
                     {"flow", c.size() >= 2 && c.back() > c.front()
                                  ? nlohmann::json(double(c.size() - 1) / (c.back() - c.front()))
                                  : nlohmann::json(nullptr)},
                     {"queue_s", c.empty() ? queue[l.name] : queue[l.name] / double(c.size())}};
  }
  const auto& m = result.verdict.metrics;
  return {{"condition", condition},
          {"seed", seed},
          {"residents", residents},
          {"out", arrivals.size()},
          {"left_behind", left},
          {"left_behind_people", left_people},
          {"t_evac", left == 0 && !arrivals.empty() ? nlohmann::json(arrivals.back())
                                                    : nlohmann::json(nullptr)},
          {"arrivals", arrivals},
          {"doors", doors},
          {"contacts", m.contacts.count("person") ? m.contacts.at("person") : 0},
          {"obstacle_contacts", m.ObstacleContacts()},
          {"closest", std::isfinite(m.min_person_distance) ? nlohmann::json(m.min_person_distance)
                                                           : nlohmann::json(nullptr)},
          {"doorway_block_s", doorway_judge.in_doorway_s()},
          {"doorway_stand_s", doorway_judge.standing_s()},
          {"localization_error_max",
           brain ? nlohmann::json(localization_error_max) : nlohmann::json(nullptr)},
          {"resident_operations", resident_operations},
          {"robot_operations", robot_operations},
          {"time", result.simulated_time}};
}

// Who was left behind (trial JSON "left_behind_people", each with its seed), one line each, the
// first kLeftBehindLines of them: mobility, whether they can operate a door, and the door they
// wait at and since when.
void PrintLeftBehind(const nlohmann::json& people) {
  constexpr std::size_t kLeftBehindLines = 12;
  for (std::size_t k = 0; k < people.size() && k < kLeftBehindLines; ++k) {
    const auto& p = people[k];
    const std::string mobility = p.at("mobility").get<std::string>();
    const std::string waiting =
        p.at("waiting_for").get<std::string>().empty()
            ? p.at("phase").get<std::string>()
            : fmt::format(
                  "waiting for {}{}", p.at("waiting_for").get<std::string>(),
                  p.at("waiting_since_s").is_null()
                      ? ""
                      : fmt::format(" since {:.1f} s", p.at("waiting_since_s").get<double>()));
    fmt::print("      seed {}: {} ({}{}), {} at ({:.1f}, {:.1f})\n",
               p.at("seed").get<std::uint64_t>(), p.at("name").get<std::string>(),
               mobility.empty() ? "" : mobility + ", ",
               p.at("can_operate").get<bool>() ? "operates doors" : "cannot operate doors", waiting,
               p.at("position")[0].get<double>(), p.at("position")[1].get<double>());
  }
  if (people.size() > kLeftBehindLines)
    fmt::print("      ... and {} more (study.json: left_behind_people)\n",
               people.size() - kLeftBehindLines);
}

// People out vs time, one curve (median) and band (10-90 %) per condition.
void DrawEvacuated(const std::map<std::string, std::vector<nlohmann::json>>& by_condition,
                   double time_limit, int residents, const std::filesystem::path& png) {
  const int W = 900, H = 520, left = 70, right = 20, top = 30, bottom = 60;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  double t_max = 1.0;
  for (const auto& [c, trials] : by_condition)
    for (const auto& t : trials)
      for (double a : t.at("arrivals").get<std::vector<double>>())
        t_max = std::max(t_max, a);
  t_max = std::min(time_limit, std::ceil(t_max / 10.0) * 10.0 + 10.0);
  const auto X = [&](double t) { return left + int((W - left - right) * t / t_max); };
  const auto Y = [&](double n) {
    return H - bottom - int((H - top - bottom) * n / std::max(1, residents));
  };
  cv::line(img, {left, H - bottom}, {W - right, H - bottom}, {0, 0, 0});
  cv::line(img, {left, top}, {left, H - bottom}, {0, 0, 0});
  for (int k = 0; k <= 5; ++k) {
    const double t = t_max * k / 5;
    cv::putText(img, fmt::format("{:.0f}", t), {X(t) - 10, H - bottom + 20},
                cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0});
    const double n = double(residents) * k / 5;
    cv::putText(img, fmt::format("{:.0f}", n), {left - 40, Y(n) + 5}, cv::FONT_HERSHEY_SIMPLEX,
                0.45, {0, 0, 0});
  }
  cv::putText(img, "time [s]", {W / 2 - 30, H - 15}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0});
  cv::putText(img, "people out", {5, top - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0});
  const std::map<std::string, cv::Scalar> colour = {
      {"no_robot", {40, 40, 200}}, {"robot", {200, 120, 30}}, {"propped_open", {40, 160, 40}}};
  int legend = 0;
  for (const auto& [c, trials] : by_condition) {
    std::vector<cv::Point> median, low, high;
    for (double t = 0.0; t <= t_max; t += t_max / 200) {
      std::vector<double> counts;
      for (const auto& trial : trials) {
        const auto a = trial.at("arrivals").get<std::vector<double>>();
        counts.push_back(double(std::upper_bound(a.begin(), a.end(), t) - a.begin()));
      }
      std::sort(counts.begin(), counts.end());
      const auto q = [&](double f) {
        return counts[std::min(counts.size() - 1, std::size_t(f * double(counts.size())))];
      };
      median.push_back({X(t), Y(q(0.5))});
      low.push_back({X(t), Y(q(0.1))});
      high.push_back({X(t), Y(q(0.9))});
    }
    const cv::Scalar col = colour.count(c) ? colour.at(c) : cv::Scalar(0, 0, 0);
    cv::polylines(img, std::vector<std::vector<cv::Point>>{low}, false,
                  col * 0.5 + cv::Scalar::all(127), 1);
    cv::polylines(img, std::vector<std::vector<cv::Point>>{high}, false,
                  col * 0.5 + cv::Scalar::all(127), 1);
    cv::polylines(img, std::vector<std::vector<cv::Point>>{median}, false, col, 2);
    cv::putText(img, c, {W - 200, top + 20 + 20 * legend++}, cv::FONT_HERSHEY_SIMPLEX, 0.5, col, 2);
  }
  if (!perception::WriteImageFile(png, img))
    throw CommandFailed(fmt::format("cannot write '{}'", png.string()));
}

void RunStudy(const StudyOptions& o) {
  if (o.trials < 1 || o.trials > 100000) throw CommandFailed("--trials must be within 1..100000");
  if (o.jobs < 1) throw CommandFailed("--jobs must be at least 1");
  if (!std::filesystem::exists(o.scenario))
    throw CommandFailed(fmt::format("'{}': no such scenario file", o.scenario));
  const std::filesystem::path dir(o.out);
  for (const char* f : {"study.json", "trials.csv", "evacuated.png"}) {
    if (std::filesystem::exists(dir / f) && !o.overwrite)
      throw CommandFailed(
          fmt::format("'{}' exists; pass --overwrite to replace it", (dir / f).string()));
  }
  twin::TwinConfig twin_config;
  o.crowd.ApplyTo(twin_config);
  const twin::Scenario loaded = twin::LoadScenario(o.scenario);
  if (!loaded.mission)
    throw CommandFailed(fmt::format(
        "{}: no 'mission' section: the study's robot condition runs the robot brain", o.scenario));
  const twin::WorldDescription world = twin::LoadSdfWorld(loaded.world_file);
  const auto hsr = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  // The building's defaults applied once (a model compiles them in), then the conditions.
  const twin::Scenario base = twin::TwinModel(loaded, world, hsr).scenario();
  bool evacuees = false;
  for (const auto& p : base.people)
    evacuees = evacuees || p.behavior == twin::PersonBehavior::kEvacuate;
  if (!evacuees)
    throw CommandFailed(fmt::format("{}: no people with behavior evacuate", o.scenario));
  // The conditions asked for, in the study's order.
  std::vector<std::string> conditions;
  for (const char* c : kConditions)
    if (std::find(o.conditions.begin(), o.conditions.end(), c) != o.conditions.end())
      conditions.emplace_back(c);
  std::map<std::string, twin::Scenario> scenarios;
  for (const std::string& c : conditions)
    scenarios[c] = ConditionScenario(base, world, c);
  CheckSeedBase(o.seed_base, o.trials, twin::kMaxScenarioSeed);
  std::vector<std::pair<std::string, std::uint64_t>> work;
  for (int i = 0; i < o.trials; ++i) {
    for (const std::string& c : conditions)
      work.emplace_back(c, o.seed_base + std::uint64_t(i));
  }
  if (!o.quiet)
    fmt::print("{}: {} trials x {} condition(s) on {} worker process(es)\n", base.name, o.trials,
               conditions.size(), std::min(o.jobs, int(work.size())));
  const std::vector<nlohmann::json> results =
      RunInWorkers(work.size(), o.jobs, !o.quiet && ::isatty(::fileno(stderr)), [&](std::size_t k) {
        return RunStudyTrial(scenarios.at(work[k].first), world, hsr, twin_config, work[k].first,
                             work[k].second);
      });
  std::map<std::string, std::vector<nlohmann::json>> by_condition;
  for (std::size_t k = 0; k < results.size(); ++k) {
    if (results[k].contains("error"))
      throw CommandFailed(fmt::format("{} seed {}: {}", work[k].first, work[k].second,
                                      results[k].at("error").get<std::string>()));
    by_condition[work[k].first].push_back(results[k]);
  }
  nlohmann::json study = {{"scenario", o.scenario},
                          {"trials", o.trials},
                          {"seed_base", o.seed_base},
                          {"crowd_rate_hz", twin_config.crowd_rate_hz},
                          {"crowd_social_rate_hz", twin_config.crowd_social_rate_hz},
                          {"conditions", nlohmann::json::array()}};
  fmt::print("\n{:<14} {:>7} {:>24} {:>12} {:>9} {:>9} {:>22}\n", "condition", "trials",
             "evacuation time [s]", "left behind", "contacts", "closest", "in doorway / standing");
  int residents = 0;
  // Per condition, each seed's evacuation time; people left behind count at the time limit
  // (censored, conservative).
  std::map<std::string, std::map<std::uint64_t, double>> t_by_seed;
  for (const auto& [c, trials] : by_condition)
    for (const auto& t : trials)
      t_by_seed[c][t.at("seed").get<std::uint64_t>()] =
          t.at("t_evac").is_null() ? base.time_limit : t.at("t_evac").get<double>();
  for (const std::string& c : conditions) {
    const auto& trials = by_condition[c];
    std::vector<double> times;
    int left = 0, contacts = 0, obstacle_contacts = 0;
    // The seeds to look at: where someone was left behind, where the robot touched someone, or a
    // wall or a door's leaf.
    std::map<std::uint64_t, int> left_by_seed, contacts_by_seed, obstacle_contacts_by_seed;
    nlohmann::json left_people = nlohmann::json::array();  // each with its seed
    double closest = std::numeric_limits<double>::infinity(), blocking = 0.0, standing = 0.0;
    std::vector<double> localization_errors;  // per trial, the worst [m]
    double worst_localization = 0.0;
    std::uint64_t worst_localization_seed = 0;
    std::map<std::string, std::vector<double>> flow, queue, by_residents, by_robot;
    for (const auto& t : trials) {
      residents = t.at("residents").get<int>();
      times.push_back(t_by_seed[c].at(t.at("seed").get<std::uint64_t>()));
      const auto seed = t.at("seed").get<std::uint64_t>();
      if (const int k = t.at("left_behind").get<int>(); k > 0) left_by_seed[seed] = k;
      for (nlohmann::json p : t.at("left_behind_people")) {
        p["seed"] = seed;
        left_people.push_back(std::move(p));
      }
      if (const int k = t.at("contacts").get<int>(); k > 0) contacts_by_seed[seed] = k;
      if (const int k = t.at("obstacle_contacts").get<int>(); k > 0)
        obstacle_contacts_by_seed[seed] = k;
      obstacle_contacts += t.at("obstacle_contacts").get<int>();
      left += t.at("left_behind").get<int>();
      contacts += t.at("contacts").get<int>();
      if (!t.at("closest").is_null()) closest = std::min(closest, t.at("closest").get<double>());
      blocking += t.at("doorway_block_s").get<double>();
      standing += t.at("doorway_stand_s").get<double>();
      if (const auto& e = t.at("localization_error_max"); !e.is_null()) {
        if (localization_errors.empty() || e.get<double>() > worst_localization)
          std::tie(worst_localization, worst_localization_seed) = std::pair(e.get<double>(), seed);
        localization_errors.push_back(e.get<double>());
      }
      for (const auto& [door, d] : t.at("doors").items()) {
        if (!d.at("flow").is_null()) flow[door].push_back(d.at("flow").get<double>());
        queue[door].push_back(d.at("queue_s").get<double>());
        by_residents[door].push_back(d.at("operated_by_residents").get<double>());
        by_robot[door].push_back(d.at("operated_by_robot").get<double>());
      }
    }
    const MedianCi ci = CalcMedianCi(times);
    fmt::print("{:<14} {:>7} {:>9.1f} [{:6.1f}, {:6.1f}] {:>12} {:>9} {:>9} {:>22}\n", c,
               trials.size(), ci.median, ci.low, ci.high, left,
               c == "robot" ? fmt::format("{}", contacts) : "-",
               c == "robot" && std::isfinite(closest) ? fmt::format("{:.2f} m", closest) : "-",
               fmt::format("{:.1f} / {:.1f} s", blocking, standing));
    const auto seeds_text = [](const std::map<std::uint64_t, int>& counts) {
      std::string text;
      for (const auto& [seed, k] : counts)
        text += fmt::format("{}{} ({})", text.empty() ? "" : ", ", seed, k);
      return text;
    };
    const auto seeds_json = [](const std::map<std::uint64_t, int>& counts) {
      nlohmann::json j = nlohmann::json::object();
      for (const auto& [seed, k] : counts)
        j[std::to_string(seed)] = k;
      return j;
    };
    if (!left_by_seed.empty())
      fmt::print("    left behind in seeds {}\n", seeds_text(left_by_seed));
    PrintLeftBehind(left_people);
    if (!contacts_by_seed.empty())
      fmt::print("    contacts in seeds {}\n", seeds_text(contacts_by_seed));
    if (!obstacle_contacts_by_seed.empty())
      fmt::print("    the robot touched a wall or a door's leaf in seeds {}\n",
                 seeds_text(obstacle_contacts_by_seed));
    nlohmann::json localization = nullptr;
    if (!localization_errors.empty()) {
      const double median = CalcMedianCi(localization_errors).median;
      fmt::print(
          "    localization error (belief against truth): worst {:.2f} m (seed {}), median "
          "of the trials' worst {:.2f} m\n",
          worst_localization, worst_localization_seed, median);
      localization = {{"max_m", worst_localization},
                      {"max_seed", worst_localization_seed},
                      {"median_of_trial_max_m", median}};
    }
    nlohmann::json doors = nlohmann::json::object();
    for (const auto& [door, q] : queue) {
      // Null (and "n/a") where no trial saw two residents through: no rate to give.
      nlohmann::json flow_median = nullptr;
      std::string flow_text = "n/a (under two through)";
      if (!flow[door].empty()) {
        flow_median = CalcMedianCi(flow[door]).median;
        flow_text = fmt::format("{:.2f} persons/s", flow_median.get<double>());
      }
      const double residents_op = CalcMedianCi(by_residents[door]).median;
      const double robot_op = CalcMedianCi(by_robot[door]).median;
      doors[door] = {{"flow_median", flow_median},
                     {"queue_s_median", CalcMedianCi(q).median},
                     {"operated_by_residents_median", residents_op},
                     {"operated_by_robot_median", robot_op}};
      fmt::print(
          "    {:<12} flow {}, queue {:.1f} s per person, opened by residents {:g}, "
          "by the robot {:g} (medians)\n",
          door, flow_text, CalcMedianCi(q).median, residents_op, robot_op);
    }
    nlohmann::json vs = nullptr;
    if (c != "no_robot" && t_by_seed.count("no_robot")) {
      const PairedDifference p = CalcPairedDifference(t_by_seed["no_robot"], t_by_seed[c], kTieSec);
      fmt::print(
          "    vs no_robot, same seeds: {:+.1f} s [{:+.1f}, {:+.1f}] (median difference, 95 %), "
          "mean {:+.1f} s; faster in {}, slower in {} of {}\n",
          p.diff.median, p.diff.low, p.diff.high, p.mean, p.lower, p.higher, p.pairs);
      vs = {{"pairs", p.pairs},
            {"t_evac_diff_median_s", p.diff.median},
            {"t_evac_diff_ci_s", {p.diff.low, p.diff.high}},
            {"t_evac_diff_mean_s", p.mean},
            {"faster", p.lower},
            {"slower", p.higher}};
    }
    study["conditions"].push_back(
        {{"condition", c},
         {"vs_no_robot", vs},
         {"t_evac_median_s", ci.median},
         {"t_evac_ci_s", {ci.low, ci.high}},
         {"left_behind", left},
         {"left_behind_by_seed", seeds_json(left_by_seed)},
         {"left_behind_people", left_people},
         {"contacts", contacts},
         {"contacts_by_seed", seeds_json(contacts_by_seed)},
         {"obstacle_contacts", obstacle_contacts},
         {"obstacle_contacts_by_seed", seeds_json(obstacle_contacts_by_seed)},
         {"closest_m", std::isfinite(closest) ? nlohmann::json(closest) : nlohmann::json(nullptr)},
         {"doorway_block_s", blocking},
         {"doorway_stand_s", standing},
         {"localization_error", localization},
         {"doors", doors}});
  }
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "study.json") << study.dump(2) << "\n";
  std::ofstream csv(dir / "trials.csv");
  csv << "condition,seed,residents,out,left_behind,t_evac,contacts,closest,doorway_block_s,"
         "doorway_stand_s,resident_operations,robot_operations,obstacle_contacts,"
         "localization_error_max\n";
  for (const auto& r : results) {
    csv << r.at("condition").get<std::string>() << "," << r.at("seed").get<std::uint64_t>() << ","
        << r.at("residents").get<int>() << "," << r.at("out").get<int>() << ","
        << r.at("left_behind").get<int>() << ","
        << (r.at("t_evac").is_null() ? "" : fmt::format("{:.2f}", r.at("t_evac").get<double>()))
        << "," << r.at("contacts").get<int>() << ","
        << (r.at("closest").is_null() ? "" : fmt::format("{:.3f}", r.at("closest").get<double>()))
        << "," << fmt::format("{:.1f}", r.at("doorway_block_s").get<double>()) << ","
        << fmt::format("{:.1f}", r.at("doorway_stand_s").get<double>()) << ","
        << r.at("resident_operations").get<int>() << "," << r.at("robot_operations").get<int>()
        << "," << r.at("obstacle_contacts").get<int>() << ","
        << (r.at("localization_error_max").is_null()
                ? ""
                : fmt::format("{:.3f}", r.at("localization_error_max").get<double>()))
        << "\n";
  }
  DrawEvacuated(by_condition, base.time_limit, residents, dir / "evacuated.png");
  fmt::print("wrote {}, {} and {}\n", (dir / "study.json").string(), (dir / "trials.csv").string(),
             (dir / "evacuated.png").string());
}

}  // namespace

void AddEvacCommand(CLI::App& app) {
  auto* evac = app.add_subcommand("evac", "Evacuation assistance: `evac study`");
  evac->require_subcommand(1);
  auto* study = evac->add_subcommand(
      "study", "Evacuation time with no robot, the robot escorting, and doors propped open");
  auto o = std::make_shared<StudyOptions>();
  study->add_option("scenario", o->scenario, "Scenario with evacuees and the robot's mission")
      ->required();
  study->add_option("--trials", o->trials, "Seeds per condition")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxTrials));
  study->add_option("--jobs", o->jobs, "Worker processes")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxJobs));
  study->add_option("--seed-base", o->seed_base, "Seed of the first trial")->capture_default_str();
  study->add_option("--out", o->out, "Output folder")->capture_default_str();
  study
      ->add_option("--conditions", o->conditions,
                   "Conditions to run (no_robot, robot, propped_open; default: all three)")
      ->check(CLI::IsMember({"no_robot", "robot", "propped_open"}))
      ->capture_default_str();
  o->crowd.AddTo(*study);
  study->add_flag("--overwrite", o->overwrite, "Replace existing output files");
  study->add_flag("-q,--quiet", o->quiet, "No progress bar");
  study->callback([o] { RunStudy(*o); });
}

}  // namespace egress::apps
