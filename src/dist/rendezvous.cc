#include "dist/rendezvous.h"

#include <charconv>
#include <cstdlib>

#include "core/error.h"

namespace cradle::dist {
namespace {

// A whole decimal integer, or nullopt.
std::optional<long> parse_integer(const std::string& text) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

// `name`'s value as an integer in [low, high]; UserError naming it otherwise.
int checked_integer(const std::string& name, const std::string& text, long low, long high) {
  const std::optional<long> value = parse_integer(text);
  if (!value || *value < low || *value > high) {
    throw UserError(name + " '" + text + "': expected an integer in [" + std::to_string(low) +
                    ", " + std::to_string(high) + "]");
  }
  return static_cast<int>(*value);
}

// Splits at commas outside brackets.
std::vector<std::string> split_top_level(const std::string& text) {
  std::vector<std::string> parts(1);
  int depth = 0;
  for (const char c : text) {
    if (c == '[') ++depth;
    if (c == ']') --depth;
    if (c == ',' && depth == 0) {
      parts.emplace_back();
    } else {
      parts.back() += c;
    }
  }
  return parts;
}

// One name with zero or more bracket groups, multiplied out in order.
void expand_name(const std::string& name, const std::string& whole, std::vector<std::string>& out) {
  const size_t open = name.find('[');
  if (open == std::string::npos) {
    if (name.empty() || name.find(']') != std::string::npos) {
      throw UserError("node list '" + whole + "': malformed host name '" + name + "'");
    }
    out.push_back(name);
    return;
  }
  const size_t close = name.find(']', open);
  if (close == std::string::npos) {
    throw UserError("node list '" + whole + "': '[' without ']'");
  }
  const std::string prefix = name.substr(0, open);
  const std::string rest = name.substr(close + 1);
  const std::string ranges = name.substr(open + 1, close - open - 1);
  for (const std::string& range : split_top_level(ranges)) {
    const size_t dash = range.find('-');
    const std::string first = range.substr(0, dash);
    const std::string last = dash == std::string::npos ? first : range.substr(dash + 1);
    const std::optional<long> low = parse_integer(first), high = parse_integer(last);
    if (!low || !high || *low < 0 || *high < *low || *high - *low > 100000) {
      throw UserError("node list '" + whole + "': bad range '" + range +
                      "' (expected N or N-M with N <= M)");
    }
    // Zero padding: the width of the first number as written.
    const size_t width = first.size();
    for (long i = *low; i <= *high; ++i) {
      std::string digits = std::to_string(i);
      if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
      expand_name(prefix + digits + rest, whole, out);
    }
  }
}

}  // namespace

EnvLookup process_env() {
  return [](const std::string& name) -> std::optional<std::string> {
    const char* value = std::getenv(name.c_str());
    if (value == nullptr) return std::nullopt;
    return std::string(value);
  };
}

std::vector<std::string> expand_nodelist(const std::string& nodelist) {
  if (nodelist.empty()) throw UserError("node list is empty: expected e.g. node[01-03,07]");
  std::vector<std::string> hosts;
  for (const std::string& name : split_top_level(nodelist)) expand_name(name, nodelist, hosts);
  return hosts;
}

Rendezvous resolve_rendezvous(const RendezvousFlags& flags, const EnvLookup& env) {
  Rendezvous r;
  r.timeout_seconds = flags.timeout_seconds;
  if (r.timeout_seconds < 1) throw UserError("--dist-timeout must be at least 1 second");
  const auto world_env = env("WORLD_SIZE"), rank_env = env("RANK");
  const auto tasks_env = env("SLURM_NTASKS"), procid_env = env("SLURM_PROCID");

  // World size and rank: flags, else torchrun's variables, else Slurm's.
  if (flags.world_size || flags.rank) {
    if (!flags.world_size || !flags.rank) {
      throw UserError("--world-size and --rank go together: give both or neither");
    }
    r.world_size = *flags.world_size;
    r.rank = *flags.rank;
    r.source = "flags";
    if (r.world_size < 1) throw UserError("--world-size must be at least 1");
  } else if (world_env || rank_env) {
    if (!world_env) throw UserError("RANK is set but WORLD_SIZE is not (set both, as torchrun)");
    if (!rank_env) throw UserError("WORLD_SIZE is set but RANK is not (set both, as torchrun)");
    r.world_size = checked_integer("WORLD_SIZE", *world_env, 1, 1 << 20);
    r.rank = checked_integer("RANK", *rank_env, 0, 1 << 20);
    if (const auto local = env("LOCAL_RANK")) {
      r.local_rank = checked_integer("LOCAL_RANK", *local, 0, 1 << 20);
    }
    r.source = "env";
  } else if (tasks_env && procid_env) {
    r.world_size = checked_integer("SLURM_NTASKS", *tasks_env, 1, 1 << 20);
    r.rank = checked_integer("SLURM_PROCID", *procid_env, 0, 1 << 20);
    if (const auto local = env("SLURM_LOCALID")) {
      r.local_rank = checked_integer("SLURM_LOCALID", *local, 0, 1 << 20);
    }
    r.source = "slurm";
  } else {
    throw UserError(
        "--distributed: no rank given (expected WORLD_SIZE and RANK as torchrun sets them, "
        "SLURM_NTASKS and SLURM_PROCID under srun, or --world-size and --rank)");
  }
  if (r.rank >= r.world_size) {
    throw UserError("rank " + std::to_string(r.rank) + " is not below the world size " +
                    std::to_string(r.world_size));
  }

  // The master: --master host[:port], else MASTER_ADDR / MASTER_PORT, else (Slurm) the job's
  // first node.
  std::optional<std::string> port_text = env("MASTER_PORT");
  if (flags.master) {
    const std::string& master = *flags.master;
    const size_t colon = master.rfind(':');
    r.master_addr = master.substr(0, colon);
    if (colon != std::string::npos) port_text = master.substr(colon + 1);
    if (r.master_addr.empty()) throw UserError("--master '" + master + "': expected host[:port]");
  } else if (const auto addr = env("MASTER_ADDR")) {
    r.master_addr = *addr;
  } else if (const auto nodes = env("SLURM_JOB_NODELIST")) {
    r.master_addr = expand_nodelist(*nodes).front();
  } else if (r.world_size == 1) {
    r.master_addr = "127.0.0.1";
  } else {
    throw UserError(
        "no master address: set MASTER_ADDR (or --master host[:port]; under Slurm "
        "SLURM_JOB_NODELIST names it)");
  }
  if (r.master_addr.empty()) throw UserError("MASTER_ADDR is empty: expected a host name or IP");
  if (port_text) {
    r.master_port =
        checked_integer(flags.master ? "--master port" : "MASTER_PORT", *port_text, 1, 65535);
  } else if (const auto job = env("SLURM_JOB_ID"); job && r.source == "slurm") {
    const std::optional<long> id = parse_integer(*job);
    if (!id || *id < 0) {
      throw UserError("SLURM_JOB_ID '" + *job + "': expected a non-negative integer");
    }
    r.master_port = kSlurmPortBase + static_cast<int>(*id % kSlurmPortSpan);
  }
  return r;
}

}  // namespace cradle::dist
