// `cradle campaign analyze RESULTS`: the tables of a results tree, by the kind of its runs (each
// seed's launch.json says it): TeachMyAgent's analysis (python/cradle/tma_analysis.py), SaMI's
// `cradle sami table` per campaign, and a table of `cradle train` runs over their seeds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/campaign.h"
#include "core/error.h"

namespace cradle::apps::campaign {

namespace fs = std::filesystem;

namespace {

// One seed folder of a results tree, as its launch.json records it.
struct SeedFolder {
  fs::path dir;
  RunKind kind = RunKind::kTma;
  std::string campaign, name;
  nlohmann::json launch;
};

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw UserError("cannot read " + file.string());
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    throw UserError(file.string() + " is not a JSON object (expected the launcher's or the run's)");
  }
  return j;
}

// RESULTS/EXP/EXP_s<seed>/launch.json of every seed.
std::vector<SeedFolder> seed_folders(const fs::path& results) {
  std::vector<SeedFolder> seeds;
  std::error_code ec;
  std::vector<fs::path> exps;
  for (const auto& e : fs::directory_iterator(results, ec)) {
    if (e.is_directory()) exps.push_back(e.path());
  }
  std::sort(exps.begin(), exps.end());
  for (const fs::path& exp : exps) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(exp, ec)) {
      if (e.is_directory() && fs::exists(e.path() / "launch.json")) dirs.push_back(e.path());
    }
    std::sort(dirs.begin(), dirs.end());
    for (const fs::path& d : dirs) {
      SeedFolder s{.dir = d, .launch = read_json(d / "launch.json")};
      const std::string run = s.launch.value("run", std::string("tma"));
      if (!parse_kind(run, s.kind)) {
        throw UserError((d / "launch.json").string() + ": run '" + shown(run) +
                        "' (expected tma, sami or train)");
      }
      s.campaign = s.launch.value("campaign", exp.filename().string());
      s.name = s.launch.value("name", exp.filename().string());
      seeds.push_back(std::move(s));
    }
  }
  return seeds;
}

// Runs a cradle subcommand; its output, or a one-line UserError with its last line.
std::string run_cradle(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {self_exe()};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto [ok, out] = capture(join_quoted(argv));
  if (!ok) {
    std::string line = last_line(out);
    if (line.starts_with("cradle: error: ")) line = line.substr(15);
    throw UserError(line.empty() ? "cradle " + args[0] + " " + args[1] + " failed" : line);
  }
  return out;
}

// SaMI: `cradle sami table` over the evaluated seeds of each campaign.
std::string analyze_sami(const std::vector<const SeedFolder*>& seeds, const fs::path& out) {
  std::map<std::string, std::vector<std::string>> by_campaign;
  size_t unevaluated = 0;
  for (const SeedFolder* s : seeds) {
    bool evaluated = false;
    for (const std::string& split : sami_splits()) {
      evaluated = evaluated || fs::exists(s->dir / ("eval_" + split + ".json"));
    }
    if (evaluated) {
      by_campaign[s->campaign].push_back(s->dir.string());
    } else {
      ++unevaluated;
    }
  }
  if (by_campaign.empty()) {
    throw UserError(
        "no SaMI seed is evaluated yet (expected eval_<split>.json: lines with --eval "
        "train,moderate,extreme, or `cradle sami evaluate --run DIR`)");
  }
  // Every table first (a bad run file is an error before anything is written).
  std::map<std::string, std::string> tables;
  for (const auto& [campaign, runs] : by_campaign) {
    std::vector<std::string> args = {"sami", "table"};
    args.insert(args.end(), runs.begin(), runs.end());
    tables[campaign] = run_cradle(args) + "\n";
  }
  std::string text;
  fs::create_directories(out);
  for (const auto& [campaign, table] : tables) {
    const fs::path file = out / ("sami_table_" + campaign + ".md");
    write_text(file, "# " + campaign + "\n\n" + table);
    text += "SaMI campaign " + campaign + " (" + std::to_string(by_campaign[campaign].size()) +
            " seeds) -> " + file.string() + "\n" + table;
  }
  if (unevaluated) {
    text += std::to_string(unevaluated) + " SaMI seeds have no evaluation yet (left out)\n";
  }
  return text;
}

struct Stat {
  std::vector<double> values;
  void add(double v) {
    if (std::isfinite(v)) values.push_back(v);
  }
  double mean() const {
    double s = 0;
    for (double v : values) s += v;
    return values.empty() ? std::nan("") : s / static_cast<double>(values.size());
  }
  // Sample standard deviation (n - 1); 0 for one value.
  double std() const {
    if (values.size() < 2) return values.empty() ? std::nan("") : 0.0;
    const double m = mean();
    double s = 0;
    for (double v : values) s += (v - m) * (v - m);
    return std::sqrt(s / static_cast<double>(values.size() - 1));
  }
};

std::string cell(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}
std::string pm(const Stat& s) {
  return s.values.empty() ? "–" : cell(s.mean()) + " ± " + cell(s.std());
}

// The last row of logs/progress.csv as column -> value; a torn or non-numeric file is an error.
std::map<std::string, double> last_progress(const fs::path& file) {
  std::ifstream in(file);
  std::string header, row, last;
  std::getline(in, header);
  while (std::getline(in, row)) {
    if (!row.empty()) last = row;
  }
  std::map<std::string, double> out;
  if (last.empty()) return out;
  std::vector<std::string> names = split_list(header), cells = split_list(last);
  if (!last.empty() && last.back() == ',') cells.push_back("");
  if (cells.size() != names.size()) {
    throw UserError(file.string() + ": the last row has " + std::to_string(cells.size()) +
                    " cells, the header " + std::to_string(names.size()) +
                    " (expected a complete progress.csv)");
  }
  for (size_t i = 0; i < names.size(); ++i) {
    if (cells[i].empty()) continue;
    char* end = nullptr;
    const double v = std::strtod(cells[i].c_str(), &end);
    if (end == cells[i].c_str() || *end != '\0') {
      throw UserError(file.string() + ": '" + shown(cells[i]) + "' in column " + names[i] +
                      " is not a number");
    }
    out[names[i]] = v;
  }
  return out;
}

// `cradle train` campaigns: each experiment's final training score and return over its seeds.
std::string analyze_train(const std::vector<const SeedFolder*>& seeds, const fs::path& out) {
  struct Row {
    std::string campaign, intrinsic, source;
    Stat steps, training_score, eval_score, final_return, eval_return;
  };
  std::map<std::string, Row> rows;
  std::vector<std::string> order;
  size_t without = 0;
  for (const SeedFolder* s : seeds) {
    const fs::path progress = s->dir / "logs" / "progress.csv";
    const std::map<std::string, double> last =
        fs::exists(progress) ? last_progress(progress) : std::map<std::string, double>{};
    if (last.empty()) {
      ++without;
      continue;
    }
    if (!rows.count(s->name)) order.push_back(s->name);
    Row& row = rows[s->name];
    row.campaign = s->campaign;
    const nlohmann::json args = s->launch.value("args", nlohmann::json::array());
    for (size_t i = 0; i + 1 < args.size(); ++i) {
      if (!args[i].is_string() || !args[i + 1].is_string()) continue;
      if (args[i] == "--intrinsic") row.intrinsic = args[i + 1].get<std::string>();
      if (args[i] == "--config" || args[i] == "--env") {
        row.source = fs::path(args[i + 1].get<std::string>()).filename().string();
      }
    }
    const auto at = [&](const char* k) {
      const auto it = last.find(k);
      return it == last.end() ? std::nan("") : it->second;
    };
    row.steps.add(at("global_step"));
    row.final_return.add(at("charts/episodic_return"));
    const fs::path eval = s->dir / "evaluation.json";
    if (fs::exists(eval)) {
      const nlohmann::json e = read_json(eval);
      // BabyBench: the training log's score and the evaluation episodes' score; an env by id:
      // the evaluation episodes' return.
      if (e.contains("training_log") && e["training_log"].contains("score") &&
          e["training_log"]["score"].is_number()) {
        row.training_score.add(e["training_log"]["score"].get<double>());
      }
      if (e.contains("score") && e["score"].is_object() && e["score"].contains("mean") &&
          e["score"]["mean"].is_number()) {
        row.eval_score.add(e["score"]["mean"].get<double>());
      }
      if (e.contains("mean_return") && e["mean_return"].is_number()) {
        row.eval_return.add(e["mean_return"].get<double>());
      }
    }
  }
  if (rows.empty()) {
    throw UserError(
        "no `cradle train` seed has a progress.csv row yet (expected RESULTS/EXP/"
        "EXP_s<seed>/logs/progress.csv)");
  }
  std::ostringstream md, csv;
  md << "| experiment | config or env | intrinsic | seeds | steps | training-log score | "
        "evaluation score | final training return | evaluation return |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  csv << "campaign,experiment,source,intrinsic,seeds,steps,training_score_mean,training_score_std,"
         "eval_score_mean,eval_score_std,final_return_mean,final_return_std,eval_return_mean,"
         "eval_return_std\n";
  for (const std::string& name : order) {
    const Row& r = rows.at(name);
    const std::string intrinsic = r.intrinsic.empty() ? "none" : r.intrinsic;
    md << "| " << name << " | " << r.source << " | " << intrinsic << " | " << r.steps.values.size()
       << " | " << cell(r.steps.mean()) << " | " << pm(r.training_score) << " | "
       << pm(r.eval_score) << " | " << pm(r.final_return) << " | " << pm(r.eval_return) << " |\n";
    csv << r.campaign << "," << name << "," << r.source << "," << intrinsic << ","
        << r.steps.values.size() << "," << cell(r.steps.mean()) << ","
        << cell(r.training_score.mean()) << "," << cell(r.training_score.std()) << ","
        << cell(r.eval_score.mean()) << "," << cell(r.eval_score.std()) << ","
        << cell(r.final_return.mean()) << "," << cell(r.final_return.std()) << ","
        << cell(r.eval_return.mean()) << "," << cell(r.eval_return.std()) << "\n";
  }
  fs::create_directories(out);
  write_text(out / "train_table.md", md.str());
  write_text(out / "train_table.csv", csv.str());
  std::string text = "train runs (mean ± std over seeds) -> " + (out / "train_table.md").string() +
                     ", " + (out / "train_table.csv").string() + "\n" + md.str();
  if (without)
    text += std::to_string(without) + " train seeds have no progress row yet (left out)\n";
  return text;
}

}  // namespace

int analyze(const std::string& results, const std::string& out_dir, const std::string& baseline) {
  std::error_code ec;
  if (!fs::is_directory(results, ec)) {
    throw UserError("results folder " + results +
                    (fs::exists(results, ec) ? " is not a folder" : " does not exist") +
                    " (expected a campaign's tree)");
  }
  const fs::path out = out_dir.empty() ? fs::path(results) / "analysis" : fs::path(out_dir);
  const std::vector<SeedFolder> seeds = seed_folders(results);
  std::vector<const SeedFolder*> tma, sami, train;
  for (const SeedFolder& s : seeds) {
    (s.kind == RunKind::kTma ? tma : s.kind == RunKind::kSami ? sami : train).push_back(&s);
  }
  if (!tma.empty() && (!sami.empty() || !train.empty())) {
    throw UserError("results folder " + results +
                    " holds TeachMyAgent runs and runs of other kinds (expected one results tree "
                    "per TeachMyAgent campaign)");
  }
  // TeachMyAgent (and a tree without launch.json files, such as a hand-made one): the paper's
  // analysis, which reads run.json where launch.json is missing.
  if (sami.empty() && train.empty()) return analyze_tma(results, out.string(), baseline);
  if (!baseline.empty()) throw UserError("--baseline is for TeachMyAgent results");
  // Both kinds' tables are made before either is written.
  std::string text;
  if (!sami.empty()) text += analyze_sami(sami, out);
  if (!train.empty()) text += analyze_train(train, out);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace cradle::apps::campaign
