#include "learn/run_files.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <system_error>

#include "core/error.h"
#include "core/sealed_file.h"
#include "learn/checkpoint.h"
#include "learn/intrinsic/reward.h"

namespace cradle::learn {
namespace {

namespace fs = std::filesystem;

constexpr const char* kRunSection = "run";
constexpr std::string_view kIntrinsicPrefix = "intrinsic/";

std::string read_all(const fs::path& file) {
  // A folder opens as a stream whose first read throws: refuse it by name first.
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw UserError("cannot read " + file.string() + ": not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UserError("cannot read " + file.string());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw UserError("cannot read " + file.string());
  return text;
}

// Appends text to a file (the aside files collect what was cut, run after run).
void append_to(const fs::path& file, std::string_view text) {
  if (text.empty()) return;
  std::ofstream out(file, std::ios::binary | std::ios::app);
  out << text;
  out.flush();
  if (!out) throw UserError("cannot write " + file.string());
}

// Complete lines (each with its '\n') and the torn rest (no final newline).
std::vector<std::string_view> split_lines(std::string_view text, std::string_view& torn) {
  std::vector<std::string_view> lines;
  size_t at = 0;
  for (size_t end; (end = text.find('\n', at)) != std::string_view::npos; at = end + 1) {
    lines.push_back(text.substr(at, end + 1 - at));
  }
  torn = text.substr(at);
  return lines;
}

// A private staging folder in the system's temp folder (mkdtemp), removed when done. Not beside
// the checkpoint: every rank of a distributed run loads the same checkpoint at once, and a process
// killed mid-save would leave the folder among the user's checkpoints.
struct Staging {
  fs::path dir;
  explicit Staging(const fs::path& file) {
    std::error_code ec;
    std::string pattern = (fs::temp_directory_path(ec) / "cradle-intrinsic-XXXXXX").string();
    if (ec || ::mkdtemp(pattern.data()) == nullptr) {
      throw UserError("cannot create a staging folder for " + file.string() + " in " +
                      fs::temp_directory_path(ec).string());
    }
    dir = pattern;
  }
  ~Staging() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

// Builds before this one staged beside the checkpoint (`<file>.intrinsic.<pid>`); a process
// killed mid-save left that folder behind. Nothing writes there now, so any such folder is stale.
void remove_old_staging(const fs::path& file) {
  std::error_code ec;
  const std::string prefix = file.filename().string() + ".intrinsic.";
  for (const auto& entry :
       fs::directory_iterator(file.parent_path().empty() ? "." : file.parent_path(), ec)) {
    if (entry.path().filename().string().starts_with(prefix)) fs::remove_all(entry.path(), ec);
  }
}

}  // namespace

void save_run_checkpoint(const fs::path& file, const Learner& learner,
                         const intrinsic::IntrinsicReward* reward, const RunState& run) {
  // The learner writes its own sealed file first; its sections are then resealed with ours.
  fs::path part = file;
  part += ".part";
  struct Remove {
    const fs::path& path;
    ~Remove() {
      std::error_code ec;
      fs::remove(path, ec);
    }
  } remove_part{part};
  try {
    learner.save(part);
  } catch (const UserError& e) {
    // Name the checkpoint, not the part file, in the one line.
    const std::string message = e.what();
    const size_t at = message.find(": cannot write");
    throw UserError(file.string() + (at == std::string::npos
                                         ? ": cannot write checkpoint (" + message + ")"
                                         : message.substr(at)));
  }
  Sections sections = read_sealed(part, "checkpoint");
  nlohmann::json state{{"steps", run.steps}, {"episodes", run.episodes}};
  if (run.intrinsic) state["intrinsic"] = *run.intrinsic;
  // Only runs that keep such logs record them: the other checkpoints stay as they were.
  if (!run.log_sizes.empty()) state["log_sizes"] = run.log_sizes;
  if (!run.teacher_steps.empty()) state["teacher_steps"] = run.teacher_steps;
  if (run.step_offset != 0) state["step_offset"] = run.step_offset;
  if (run.learner_resets != 0) state["learner_resets"] = run.learner_resets;
  if (!run.experiment.empty()) state["experiment"] = run.experiment;
  sections[kRunSection] = state.dump();
  if (reward) {
    const Staging staging(file);
    reward->save(staging.dir);
    for (const auto& entry : fs::directory_iterator(staging.dir)) {
      sections[std::string(kIntrinsicPrefix) + entry.path().filename().string()] =
          read_all(entry.path());
    }
  }
  write_sealed(file, sections);
  remove_old_staging(file);
}

RunState load_run_state(const fs::path& file, intrinsic::IntrinsicReward* reward) {
  const Sections sections = read_sealed(file, "checkpoint");
  const auto run = sections.find(kRunSection);
  if (run == sections.end()) {
    throw UserError(file.string() + ": a checkpoint without run state (not written by train)");
  }
  RunState state;
  const nlohmann::json j = nlohmann::json::parse(run->second, nullptr, false);
  if (!j.is_object() || !j.contains("steps") || !j["steps"].is_number_integer() ||
      !j.contains("episodes") || !j["episodes"].is_number_integer()) {
    throw UserError(file.string() + ": checkpoint run state is malformed");
  }
  state.steps = j["steps"].get<long>();
  state.episodes = j["episodes"].get<long>();
  if (j.contains("intrinsic")) {
    if (!j["intrinsic"].is_string())
      throw UserError(file.string() + ": checkpoint run state is malformed");
    state.intrinsic = j["intrinsic"].get<std::string>();
  }
  for (const char* key : {"step_offset", "learner_resets"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_number_unsigned())
      throw UserError(file.string() + ": checkpoint run state is malformed (" + key + ")");
    (key == std::string("step_offset") ? state.step_offset : state.learner_resets) =
        j[key].get<long>();
  }
  if (j.contains("experiment")) {
    if (!j["experiment"].is_string())
      throw UserError(file.string() + ": checkpoint run state is malformed (experiment)");
    state.experiment = j["experiment"].get<std::string>();
  }
  // Counts by paths inside the run folder (sizes in bytes, teacher steps).
  for (const char* key : {"log_sizes", "teacher_steps"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_object())
      throw UserError(file.string() + ": checkpoint run state is malformed (" + key + ")");
    for (const auto& [name, count] : j[key].items()) {
      const fs::path path(name);
      bool inside = !name.empty() && path.is_relative();
      for (const fs::path& part : path) inside = inside && part != "..";
      if (!inside || !count.is_number_unsigned())
        throw UserError(file.string() + ": checkpoint run state is malformed (" + key + ": " +
                        name + ")");
      if (key == std::string("log_sizes"))
        state.log_sizes[name] = count.get<std::uintmax_t>();
      else
        state.teacher_steps[name] = count.get<long>();
    }
  }
  if (reward) {
    const Staging staging(file);
    for (const auto& [name, bytes] : sections) {
      if (!name.starts_with(kIntrinsicPrefix)) continue;
      const std::string base = name.substr(kIntrinsicPrefix.size());
      if (base.empty() || base.find('/') != std::string::npos || base.starts_with(".")) {
        throw UserError(file.string() + ": bad intrinsic section name '" + name + "'");
      }
      std::ofstream(staging.dir / base, std::ios::binary) << bytes;
    }
    try {
      reward->load(staging.dir);
    } catch (const UserError& e) {
      throw UserError(file.string() + ": no matching intrinsic-reward state (" + e.what() +
                      "); was it trained with another --intrinsic?");
    }
  }
  return state;
}

void cut_to_checkpoint(const fs::path& file, std::uintmax_t size) {
  std::error_code ec;
  if (fs::exists(file, ec) && !fs::is_regular_file(file, ec))
    throw UserError("--resume: '" + file.string() + "' is not a file (expected the run's log)");
  const std::string text = fs::exists(file, ec) ? read_all(file) : std::string();
  if (text.size() < size) {
    throw UserError("--resume: '" + file.string() + "' is shorter than at the checkpoint (" +
                    std::to_string(text.size()) + " < " + std::to_string(size) + " bytes)");
  }
  if (text.size() == size) return;
  const fs::path aside =
      file.parent_path() / (file.stem().string() + ".after-checkpoint" + file.extension().string());
  append_to(aside, std::string_view(text).substr(size));
  write_atomically(file, std::string_view(text).substr(0, size));
  std::cerr << file.filename().string() << ": lines after the checkpoint kept in " << aside.string()
            << "\n";
}

long cut_training_log(const fs::path& log, long episodes) {
  std::error_code ec;
  if (!fs::exists(log, ec)) return 0;
  const std::string text = read_all(log);
  std::string_view torn;
  const std::vector<std::string_view> lines = split_lines(text, torn);
  // Entries are the non-blank lines; the cut falls after the episodes-th.
  long kept = 0;
  size_t cut = 0;
  for (const std::string_view line : lines) {
    if (kept == episodes) break;
    cut += line.size();
    if (line.find_first_not_of(" \t\r\n") != std::string_view::npos) ++kept;
  }
  if (cut == text.size()) return kept;
  append_to(fs::path(log).replace_filename("training.after-checkpoint.jsonl"),
            std::string(text.substr(cut)) + (torn.empty() ? "" : "\n"));
  write_atomically(log, std::string_view(text).substr(0, cut));
  return kept;
}

fs::path keep_aside_before_resume(const fs::path& file) {
  const fs::path folder = file.parent_path();
  const std::string stem = file.stem().string(), extension = file.extension().string();
  fs::path kept = folder / (stem + ".before-resume" + extension);
  for (int k = 2; fs::exists(kept); ++k) {
    kept = folder / (stem + ".before-resume-" + std::to_string(k) + extension);
  }
  std::error_code ec;
  fs::rename(file, kept, ec);
  if (ec) throw UserError("cannot rename '" + file.string() + "': " + ec.message());
  return kept;
}

ProgressCut cut_progress(const fs::path& csv, const std::string& header, long step) {
  ProgressCut result;
  std::error_code ec;
  if (!fs::exists(csv, ec)) return result;
  if (fs::is_directory(csv, ec))
    throw UserError(csv.string() + " is a folder; expected the run's progress.csv");
  const std::string text = read_all(csv);
  std::string_view torn;
  const std::vector<std::string_view> lines = split_lines(text, torn);
  const fs::path folder = csv.parent_path();

  // Other columns (another version's file): kept whole beside the new one.
  if (lines.empty() || lines[0] != header + "\n") {
    result.kept_aside = keep_aside_before_resume(csv);
    return result;
  }

  // Same columns: rows up to the checkpoint's step stay, the rest goes aside.
  std::string keep(lines[0]), aside;
  for (size_t k = 1; k < lines.size(); ++k) {
    const std::string_view line = lines[k];
    char* stop = nullptr;
    const std::string cell(line.substr(0, line.find_first_of(",\n")));
    const double row_step = std::strtod(cell.c_str(), &stop);
    if (cell.empty() || *stop != '\0' || !(row_step <= static_cast<double>(step))) {
      aside += line;
      continue;
    }
    keep += line;
    std::vector<double>& row = result.rows.emplace_back();
    size_t at = 0;
    const std::string body(line.substr(0, line.size() - 1));
    for (;;) {
      const size_t comma = body.find(',', at);
      const std::string value = body.substr(at, comma == std::string::npos ? comma : comma - at);
      row.push_back(value.empty() ? std::nan("") : std::strtod(value.c_str(), nullptr));
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
  }
  if (!torn.empty()) aside += std::string(torn) + "\n";
  result.append = true;
  if (aside.empty()) return result;
  const fs::path aside_file = folder / "progress.after-checkpoint.csv";
  append_to(aside_file, (fs::exists(aside_file) ? "" : header + "\n") + aside);
  write_atomically(csv, keep);
  result.kept_aside = aside_file;
  return result;
}

void check_finite_losses(const TrainStats& stats, const fs::path& checkpoint) {
  for (const auto& [name, value] : stats.losses) {
    // explained_variance is NaN by definition when the returns do not vary.
    if (std::isfinite(value) || name == "explained_variance") continue;
    std::error_code ec;
    const std::string kept = fs::exists(checkpoint, ec)
                                 ? "the last good checkpoint is " + checkpoint.string()
                                 : "no checkpoint was written";
    throw UserError("the update ending at step " + std::to_string(stats.steps) + " diverged (" +
                    name + " = " + std::to_string(value) + "); training stopped, " + kept +
                    " (try a smaller learning_rate or max_grad_norm)");
  }
}

std::ofstream continue_log(const fs::path& file, const std::string& header, bool resume) {
  bool fresh = !resume;
  if (resume) {
    std::ifstream in(file);
    std::string first;
    if (!in || !std::getline(in, first)) {
      fresh = true;
    } else if (first != header) {
      in.close();
      const fs::path kept = keep_aside_before_resume(file);
      std::cerr << file.filename().string() << ": written with other columns, kept whole as "
                << kept.string() << "; a fresh one begins\n";
      fresh = true;
    }
  }
  std::ofstream out(file, fresh ? std::ios::trunc : std::ios::app);
  if (!out) throw UserError("cannot write '" + file.string() + "'");
  if (fresh) out << header << "\n";
  return out;
}

}  // namespace cradle::learn
