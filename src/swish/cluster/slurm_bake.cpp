#include "swish/cluster/slurm_bake.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include <tbb/global_control.h>

#include "swish/bake/cloth/pose_driver.hpp"
#include "swish/bake/cloth/simulated_pose_file.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/cluster/pose_list_file.hpp"
#include "swish/cluster/process.hpp"
#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/files/atomic_write.hpp"

namespace swish::cluster {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// Share of a task's time limit the sizing fills; the rest is for nodes slower than the measuring one.
constexpr double kTimeLimitShare = 0.8;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char s[32];
  std::strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return s;
}

std::string hostName() {
  char h[256] = {};
  gethostname(h, sizeof h - 1);
  return h;
}

std::string duration(double s) {
  char b[64];
  if (s < 120)
    std::snprintf(b, sizeof b, "%.0f s", s);
  else if (s < 7200)
    std::snprintf(b, sizeof b, "%.1f min", s / 60);
  else
    std::snprintf(b, sizeof b, "%.1f h", s / 3600);
  return b;
}

// The digest of the recipe's part 1 settings that a pose list was made from.
uint64_t settingsDigest(const bake::DatasetBuildSettings& s) {
  const std::string j = s.toJson().dump();
  return fnv1a(j.data(), j.size());
}

std::string envOr(const char* name, const std::string& fallback = {}) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

fs::path selfExecutable() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec)
    throw Error("cannot find this program's own path (/proc/self/exe): " + ec.message() + "; give --swish-binary");
  return p;
}

nlohmann::json readJsonFile(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file.string() + ": not valid JSON (" + std::string(e.what()) + ")");
  }
}

// The job ids of a submission that squeue still lists (pending, running, requeued...).
struct QueueEntry {
  std::string id, state, reason;
};
std::optional<std::vector<QueueEntry>> queueOf(const std::vector<std::string>& jobs, std::string* error) {
  std::string list;
  for (const std::string& j : jobs)
    if (!j.empty()) list += (list.empty() ? "" : ",") + j;
  if (list.empty()) return std::vector<QueueEntry>{};
  const CommandResult r = runCommand({"squeue", "-h", "-r", "-j", list, "-o", "%i|%T|%r"});
  if (r.exitCode != 0) {
    // squeue exits 1 with "Invalid job id specified" once every job has left the controller's memory.
    if (r.err.find("Invalid job id") != std::string::npos) return std::vector<QueueEntry>{};
    if (error) *error = "squeue failed (exit " + std::to_string(r.exitCode) + "): " + r.err;
    return std::nullopt;
  }
  std::vector<QueueEntry> q;
  size_t at = 0;
  while (at < r.out.size()) {
    const size_t end = std::min(r.out.find('\n', at), r.out.size());
    const std::string line = r.out.substr(at, end - at);
    at = end + 1;
    const size_t a = line.find('|'), b = line.find('|', a == std::string::npos ? a : a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    q.push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), line.substr(b + 1)});
  }
  return q;
}

std::vector<std::string> submittedJobs(const nlohmann::json& sub) {
  std::vector<std::string> ids;
  for (const char* k : {"part1", "dataset", "part2"})
    if (sub.contains("jobs") && sub["jobs"].contains(k) && sub["jobs"][k].is_string()) ids.push_back(sub["jobs"][k]);
  return ids;
}

// sbatch --parsable prints "jobid" or "jobid;cluster".
std::string submit(const std::vector<std::string>& argv, const std::function<void(const std::string&)>& log) {
  if (log) log("slurm: " + shellLine(argv));
  const CommandResult r = runCommand(argv);
  std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
  if (r.exitCode != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw Error("sbatch failed (exit " + std::to_string(r.exitCode) + ")" +
                (r.exitCode == 127 ? ": sbatch is not installed here (Debian: slurm-client)" : "") + ": " + r.err +
                (r.out.empty() ? "" : " " + r.out));
  return id;
}

void writeScript(const fs::path& file, const std::string& what, const std::vector<std::string>& command) {
  std::string text =
      "#!/bin/bash\n# " + what +
      "\n# Written by `swish bake --slurm` (src/swish/cluster/slurm_bake.hpp); submitting again rewrites "
      "it.\n# The sbatch options are on the sbatch command line (see submission.json).\nset -e\nexec " +
      shellLine(command) + "\n";
  writeTextFileAtomic(file, text);
  fs::permissions(file, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add);
}

struct PoseFileState {
  std::vector<uint8_t> state;   // 0 missing, 1 done, 2 failed (done, left out)
  std::vector<double> seconds;  // of the finished ones
};
PoseFileState scanPoseFiles(const fs::path& simDir, const std::vector<uint64_t>& fingerprints) {
  PoseFileState st;
  st.state.assign(fingerprints.size(), 0);
  for (uint32_t i = 0; i < fingerprints.size(); ++i) {
    const auto h = bake::peekSimulatedPose(bake::simulatedPosePath(simDir, i));
    if (!h || h->poseId != i || h->fingerprint != fingerprints[i]) continue;
    st.state[i] = h->ok ? 1 : 2;
    st.seconds.push_back(h->seconds);
  }
  return st;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

fs::path shardFile(const fs::path& dir, size_t shard) {
  char name[40];
  std::snprintf(name, sizeof name, "shard_%06zu.json", shard);
  return dir / "shards" / name;
}

}  // namespace

fs::path slurmDir(const bake::BakeConfig& cfg) { return cfg.work / "slurm"; }

double parseSlurmTime(const std::string& text) {
  auto bad = [&]() -> Error {
    return Error("time limit '" + text +
                 "': not a Slurm time (minutes, minutes:seconds, hours:minutes:seconds, days-hours, "
                 "days-hours:minutes or days-hours:minutes:seconds)");
  };
  if (text.empty() || text.find_first_not_of("0123456789:-") != std::string::npos) throw bad();
  auto num = [&](const std::string& s) -> double {
    if (s.empty() || s.size() > 9) throw bad();
    return double(std::stoul(s));
  };
  std::vector<std::string> parts;
  std::string rest = text;
  double days = 0;
  if (const size_t dash = rest.find('-'); dash != std::string::npos) {
    days = num(rest.substr(0, dash));
    rest = rest.substr(dash + 1);
    if (rest.find('-') != std::string::npos) throw bad();
  }
  size_t at = 0;
  while (true) {
    const size_t c = rest.find(':', at);
    parts.push_back(rest.substr(at, c == std::string::npos ? std::string::npos : c - at));
    if (c == std::string::npos) break;
    at = c + 1;
  }
  if (parts.size() > 3) throw bad();
  double s = 0;
  if (text.find('-') != std::string::npos) {  // days-hours[:minutes[:seconds]]
    s = days * 86400 + num(parts[0]) * 3600;
    if (parts.size() > 1) s += num(parts[1]) * 60;
    if (parts.size() > 2) s += num(parts[2]);
  } else if (parts.size() == 1) {
    s = num(parts[0]) * 60;
  } else if (parts.size() == 2) {
    s = num(parts[0]) * 60 + num(parts[1]);
  } else {
    s = num(parts[0]) * 3600 + num(parts[1]) * 60 + num(parts[2]);
  }
  if (s <= 0) throw Error("time limit '" + text + "': must be more than zero");
  return s;
}

std::string arrayIndexList(const std::vector<size_t>& idx) {
  std::string out;
  for (size_t i = 0; i < idx.size();) {
    size_t j = i;
    while (j + 1 < idx.size() && idx[j + 1] == idx[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(idx[i]);
    if (j > i) {
      out += '-';
      out += std::to_string(idx[j]);
    }
    i = j + 1;
  }
  return out;
}

ShardPlan planShards(size_t poses, double secondsPerPose, double setupSeconds, double limit, int cpus,
                     size_t override) {
  if (cpus < 1) throw Error("cpus per task must be 1 or more");
  if (!(secondsPerPose > 0.0)) throw Error("seconds per pose must be more than zero");
  ShardPlan p;
  if (override > 0) {
    p.posesPerTask = override;
  } else {
    const double budget = kTimeLimitShare * limit - setupSeconds;
    const double rounds = std::floor(budget / secondsPerPose);  // poses one cpu does in the budget
    if (rounds < 1.0) {
      char m[300];
      std::snprintf(m, sizeof m,
                    "a task's time limit of %s leaves no time for one pose: %.0f %% of it is %.1f s, the task's setup "
                    "takes %.1f s and one pose %.1f s on one core; give a longer --time",
                    duration(limit).c_str(), 100 * kTimeLimitShare, kTimeLimitShare * limit, setupSeconds,
                    secondsPerPose);
      throw Error(m);
    }
    p.posesPerTask = size_t(rounds) * size_t(cpus);
  }
  p.posesPerTask = std::max<size_t>(1, std::min(p.posesPerTask, std::max<size_t>(poses, 1)));
  p.shards = poses == 0 ? 0 : (poses + p.posesPerTask - 1) / p.posesPerTask;
  p.taskSeconds = setupSeconds + std::ceil(double(p.posesPerTask) / double(cpus)) * secondsPerPose;
  return p;
}

nlohmann::json submitSlurmBake(const bake::BakeConfig& cfg, const fs::path& configFile, const SlurmSubmitOptions& o) {
  auto log = [&](const std::string& l) {
    if (o.log) o.log(l);
  };
  if (!cfg.part1)
    throw Error("bake '" + cfg.name +
                "': the recipe has no \"part1\" section, so there is nothing to simulate on a "
                "cluster; part 2 alone runs as `swish bake " +
                configFile.string() + "` (in one sbatch job if you like)");
  if (o.cpusPerTask < 1) throw Error("--cpus-per-task must be 1 or more");
  const double limit = parseSlurmTime(o.timeLimit);
  if (!o.finalTimeLimit.empty()) parseSlurmTime(o.finalTimeLimit);
  const fs::path dir = slurmDir(cfg);
  const fs::path subFile = dir / "submission.json";

  // One submission per work folder at a time: two arrays would write the same files.
  if (fs::exists(subFile) && !o.dryRun) {
    const nlohmann::json old = readJsonFile(subFile);
    std::string err;
    const auto q = queueOf(submittedJobs(old), &err);
    if (!q)
      throw Error("cannot tell whether the earlier submission (" + subFile.string() + ") is still queued: " + err);
    if (!q->empty()) {
      std::string ids;
      for (const std::string& j : submittedJobs(old)) ids += " " + j;
      throw Error("the bake submitted from " + dir.string() + " at " + old.value("submitted", std::string("?")) +
                  " still has jobs in the queue (" + std::to_string(q->size()) + " entries, jobs" + ids +
                  "): wait for them, or cancel them (scancel" + ids + ") and submit again");
    }
  }

  const auto t0 = Clock::now();
  // The local bake's training poses (part1.holdout's subjects out): the array's pose list must be the
  // one the part 1 job then checks it against.
  const bake::DatasetBuildSettings s = bake::bakeTrainingSettings(cfg);
  log("slurm: part 1 up to the simulation (character, clips, sampling, thinning), once, here");
  const bake::DatasetPosePlan plan = bake::planDatasetPoses(s, o.log);
  double setup = 0.0;
  for (const auto& st : plan.result.steps)
    if (st.name == "character" || st.name == "simulation setup") setup += st.seconds;
  PoseList list;
  list.fingerprint = plan.fingerprint();
  list.settingsDigest = settingsDigest(s);
  list.poses = plan.toSimulate;
  list.poseFingerprints = plan.poseFingerprints();
  fs::create_directories(dir / "logs");
  fs::create_directories(dir / "shards");
  const fs::path listFile = dir / "poses.bin";
  writePoseList(listFile, list);
  const size_t n = list.poses.size();
  log("slurm: " + std::to_string(n) + " poses, pose list " + fingerprintHex(list.fingerprint) + " -> " +
      listFile.string());
  // Shard progress of an earlier submission describes other shards.
  for (const auto& e : fs::directory_iterator(dir / "shards")) fs::remove(e.path());

  // Seconds per pose (one pose, one core).
  const fs::path simDir = cfg.simulationDir();
  PoseFileState files = scanPoseFiles(simDir, list.poseFingerprints);
  double spp = o.secondsPerPose;
  std::string sppSource = "given (--seconds-per-pose)";
  if (spp <= 0.0 && files.seconds.size() >= 3) {
    spp = median(files.seconds);
    sppSource = "median of the " + std::to_string(files.seconds.size()) + " poses already simulated";
  }
  if (spp <= 0.0) {
    const auto first = std::find(files.state.begin(), files.state.end(), uint8_t(0));
    if (first != files.state.end()) {
      const uint32_t id = uint32_t(first - files.state.begin());
      log("slurm: measuring: simulating pose " + std::to_string(id) + " here on one core (its file is kept)");
      const auto tm = Clock::now();
      bake::simulatePoses(plan.shapes->solver(), list.poses, {id}, simDir, {}, 1);
      spp = since(tm);
      sppSource = "measured on " + hostName() + " (pose " + std::to_string(id) + ", one core)";
      files = scanPoseFiles(simDir, list.poseFingerprints);
    } else {
      spp = files.seconds.empty() ? 1.0 : median(files.seconds);
      sppSource = "every pose is simulated already";
    }
  }
  const ShardPlan sp = planShards(n, spp, setup, limit, o.cpusPerTask, o.posesPerTask);
  std::vector<size_t> shards;
  size_t todo = 0;
  for (size_t k = 0; k < sp.shards; ++k) {
    size_t left = 0;
    for (size_t i = k * sp.posesPerTask; i < std::min(n, (k + 1) * sp.posesPerTask); ++i) left += files.state[i] == 0;
    if (left) shards.push_back(k);
    todo += left;
  }
  {
    char line[400];
    std::snprintf(line, sizeof line,
                  "slurm: %.2f s per pose (%s), task setup %.1f s; %zu poses per task -> %zu shards, a full task about "
                  "%s of its %s limit; %zu poses to simulate in %zu array tasks",
                  spp, sppSource.c_str(), setup, sp.posesPerTask, sp.shards, duration(sp.taskSeconds).c_str(),
                  o.timeLimit.c_str(), todo, shards.size());
    log(line);
    if (o.posesPerTask > 0 && sp.taskSeconds > limit)
      log("slurm: warning: --poses-per-task " + std::to_string(o.posesPerTask) + " takes about " +
          duration(sp.taskSeconds) + " per task, more than the time limit " + o.timeLimit +
          ": Slurm will stop such tasks (their finished poses are kept; submit again to go on)");
  }

  // The scripts: each job runs this program on the same recipe, with the pose list's fingerprint.
  const fs::path exe = o.swishExecutable.empty() ? selfExecutable() : fs::absolute(o.swishExecutable);
  const fs::path config = fs::absolute(configFile);
  const std::string fp = fingerprintHex(list.fingerprint);
  writeScript(dir / "part1.sbatch", "part 1: array task k simulates the poses of shard k",
              {exe.string(), "bake", config.string(), "--slurm-task", "part1", "--pose-list", fp, "--shard-size",
               std::to_string(sp.posesPerTask)});
  writeScript(dir / "dataset.sbatch", "part 1 after the array: transfer, normal maps, the dataset folder",
              {exe.string(), "bake", config.string(), "--slurm-task", "dataset", "--pose-list", fp});
  writeScript(dir / "part2.sbatch", "part 2: the model and its report",
              {exe.string(), "bake", config.string(), "--slurm-task", "part2", "--pose-list", fp});

  auto common = [&](const std::string& stage, const std::string& time, const std::string& output) {
    std::vector<std::string> a = {"sbatch",
                                  "--parsable",
                                  "--job-name=swish-" + cfg.name + "-" + stage,
                                  "--chdir=" + dir.string(),
                                  "--output=" + (dir / "logs" / output).string(),
                                  "--open-mode=append",
                                  "--cpus-per-task=" + std::to_string(o.cpusPerTask)};
    if (!time.empty()) a.push_back("--time=" + time);
    if (!o.partition.empty()) a.push_back("--partition=" + o.partition);
    if (!o.account.empty()) a.push_back("--account=" + o.account);
    return a;
  };
  auto finish = [&](std::vector<std::string> a, const std::string& script) {
    a.insert(a.end(), o.sbatchArgs.begin(), o.sbatchArgs.end());
    a.push_back((dir / script).string());
    return a;
  };
  nlohmann::json jobs = nlohmann::json::object();
  nlohmann::json lines = nlohmann::json::array();
  std::vector<std::string> submitted;
  auto run = [&](const std::vector<std::string>& argv) -> std::string {
    lines.push_back(shellLine(argv));
    if (o.dryRun) {
      log("slurm: (dry run) " + shellLine(argv));
      return "";
    }
    try {
      std::string id = submit(argv, o.log);
      submitted.push_back(id);
      return id;
    } catch (const Error&) {
      if (!submitted.empty()) {  // no half submission left behind
        std::vector<std::string> cancel = {"scancel"};
        cancel.insert(cancel.end(), submitted.begin(), submitted.end());
        runCommand(cancel);
      }
      throw;
    }
  };
  std::string array, dataset, part2;
  if (!shards.empty()) {
    std::vector<std::string> a = common("part1", o.timeLimit, "part1_%A_%a.out");
    a.push_back("--array=" + arrayIndexList(shards) + (o.maxRunning > 0 ? "%" + std::to_string(o.maxRunning) : ""));
    a.push_back("--requeue");
    array = run(finish(a, "part1.sbatch"));
  }
  {
    std::vector<std::string> a = common("dataset", o.finalTimeLimit, "dataset_%j.out");
    if (!shards.empty()) {
      a.push_back("--dependency=afterok:" + (o.dryRun ? std::string("<part1>") : array));
      a.push_back("--kill-on-invalid-dep=yes");
    }
    dataset = run(finish(a, "dataset.sbatch"));
  }
  {
    std::vector<std::string> a = common("part2", o.finalTimeLimit, "part2_%j.out");
    a.push_back("--dependency=afterok:" + (o.dryRun ? std::string("<dataset>") : dataset));
    a.push_back("--kill-on-invalid-dep=yes");
    part2 = run(finish(a, "part2.sbatch"));
  }
  if (!array.empty()) jobs["part1"] = array;
  jobs["dataset"] = dataset;
  jobs["part2"] = part2;

  nlohmann::json sub = {{"name", cfg.name},
                        {"config", config.string()},
                        {"submitted", utcNow()},
                        {"submitted_from", hostName()},
                        {"dry_run", o.dryRun},
                        {"pose_list", fp},
                        {"pose_list_file", listFile.string()},
                        {"poses", n},
                        {"poses_to_simulate", todo},
                        {"shard_size", sp.posesPerTask},
                        {"shards", sp.shards},
                        {"array_indices", arrayIndexList(shards)},
                        {"seconds_per_pose", spp},
                        {"seconds_per_pose_source", sppSource},
                        {"task_setup_seconds", setup},
                        {"estimated_task_seconds", sp.taskSeconds},
                        {"cpus_per_task", o.cpusPerTask},
                        {"time_limit", o.timeLimit},
                        {"max_running", o.maxRunning},
                        {"jobs", jobs},
                        {"sbatch", lines},
                        {"prepare_seconds", since(t0)}};
  writeTextFileAtomic(subFile, sub.dump(2) + "\n");
  if (o.dryRun)
    log("slurm: dry run: nothing submitted; the scripts and the pose list are in " + dir.string());
  else
    log("slurm: submitted: part 1 " +
        (array.empty() ? std::string("(nothing left to simulate)") : "array job " + array) + ", dataset job " +
        dataset + ", part 2 job " + part2 + "; follow it with `swish bake " + configFile.string() + " --status`");
  return sub;
}

void runSlurmStage(const bake::BakeConfig& cfg, const std::string& stage, uint64_t poseList, size_t shardSize,
                   const std::function<void(const std::string&)>& logFn) {
  auto log = [&](const std::string& l) {
    if (logFn) logFn(l);
  };
  if (stage != "part1" && stage != "dataset" && stage != "part2")
    throw Error("--slurm-task '" + stage + "': expected part1, dataset or part2");
  if (!cfg.part1) throw Error("bake '" + cfg.name + "': a cluster bake needs the recipe's \"part1\" section");
  const int cpus = std::atoi(envOr("SLURM_CPUS_PER_TASK", "0").c_str());
  std::optional<tbb::global_control> limitThreads;
  if (cpus > 0) limitThreads.emplace(tbb::global_control::max_allowed_parallelism, size_t(cpus));

  // The guard: this job was submitted for one pose list; the folder must hold that one, and the recipe
  // must still be the one it was made from.
  const fs::path dir = slurmDir(cfg);
  const PoseList list = readPoseList(dir / "poses.bin");
  if (list.fingerprint != poseList)
    throw Error((dir / "poses.bin").string() + " holds the pose list " + fingerprintHex(list.fingerprint) +
                ", but this job was submitted for " + fingerprintHex(poseList) +
                ": the bake was submitted again with another recipe; this job stops without writing anything");
  const bake::DatasetBuildSettings s = bake::bakeTrainingSettings(cfg);  // as the submission digested it
  if (settingsDigest(s) != list.settingsDigest)
    throw Error("the recipe's part 1 settings changed after `swish bake --slurm` wrote " +
                (dir / "poses.bin").string() + "; this job stops without writing anything: submit again");

  if (stage == "dataset" || stage == "part2") {
    bake::BakeRunOptions run;
    run.log = logFn;
    run.part1 = stage == "dataset";
    run.part2 = stage == "part2";
    run.simulatedPoseList = poseList;
    bake::runBake(cfg, run);
    return;
  }

  // An array task: its shard of the pose list.
  const std::string task = envOr("SLURM_ARRAY_TASK_ID");
  if (task.empty() || task.find_first_not_of("0123456789") != std::string::npos)
    throw Error("--slurm-task part1 runs inside a Slurm array task (SLURM_ARRAY_TASK_ID is '" + task + "')");
  if (shardSize == 0) throw Error("--slurm-task part1 needs --shard-size");
  const size_t shard = std::stoul(task), first = shard * shardSize;
  if (first >= list.poses.size())
    throw Error("array task " + task + ": shard " + task + " of " + std::to_string(shardSize) +
                " poses starts past the " + std::to_string(list.poses.size()) + " poses");
  const size_t last = std::min(list.poses.size(), first + shardSize);
  const std::string jobId = envOr("SLURM_ARRAY_JOB_ID", "?") + "_" + task;
  const std::string restart = envOr("SLURM_RESTART_COUNT", "0");
  log("shard " + task + ": poses " + std::to_string(first) + " to " + std::to_string(last - 1) + " of " +
      std::to_string(list.poses.size()) + ", job " + jobId + " on " + hostName() + ", restart " + restart + ", " +
      std::to_string(cpus > 0 ? cpus : 0) + " cpus");
  const auto t0 = Clock::now();
  const Character character = bake::loadDatasetCharacter(s);
  const bake::PoseShapeSimulator shapes(character, s.poseShape());
  std::vector<uint32_t> ids;
  for (size_t i = first; i < last; ++i) {
    if (bake::poseFingerprint(shapes.solver(), list.poses[i]) != list.poseFingerprints[i])
      throw Error("shard " + task + ": pose " + std::to_string(i) +
                  ": the simulation set up here differs from the submitting machine's (another swish build, or "
                  "the character's files changed); this job stops without writing anything");
    ids.push_back(uint32_t(i));
  }
  const double setup = since(t0);
  const fs::path progressFile = shardFile(dir, shard);
  auto writeProgress = [&](const std::string& state, size_t done, size_t simulated, size_t reused, size_t failed) {
    const nlohmann::json j = {{"shard", shard},
                              {"first", first},
                              {"count", ids.size()},
                              {"done", done},
                              {"simulated", simulated},
                              {"reused", reused},
                              {"failed", failed},
                              {"state", state},
                              {"job", jobId},
                              {"restart", std::stoi(restart)},
                              {"host", hostName()},
                              {"updated", utcNow()},
                              {"pose_list", fingerprintHex(poseList)}};
    writeTextFileAtomic(progressFile, j.dump(2) + "\n");
  };
  size_t startDone = 0;
  bool first_call = true;
  auto last_line = Clock::now() - std::chrono::hours(1);
  const auto simStart = Clock::now();
  const bake::PoseSimulationRun r = bake::simulatePoses(
      shapes.solver(), list.poses, ids, cfg.simulationDir(),
      [&](size_t done, size_t total, double left) {
        if (first_call) {  // the first call counts the poses found finished
          first_call = false;
          startDone = done;
          log("shard " + task + ": " + std::to_string(done) + " of " + std::to_string(total) +
              " poses finished before (kept), " + std::to_string(total - done) + " to simulate");
        }
        writeProgress("running", done, done - startDone, startDone, 0);
        if (done == total || since(last_line) > 5.0) {
          last_line = Clock::now();
          char line[200];
          std::snprintf(line, sizeof line, "shard %s: %zu/%zu poses, %.1f s elapsed, about %.1f s left", task.c_str(),
                        done, total, since(simStart), left);
          log(line);
        }
        return true;
      },
      cpus);
  writeProgress("done", r.simulated + r.reused, r.simulated, r.reused, r.failed);
  char line[240];
  std::snprintf(line, sizeof line,
                "shard %s: done in %.1f s (setup %.1f s): %zu simulated, %zu finished before, %zu failed (left out)",
                task.c_str(), since(t0), setup, r.simulated, r.reused, r.failed);
  log(line);
  for (const auto& [id, why] : r.failures) log("shard " + task + ": pose " + std::to_string(id) + " failed: " + why);
}

std::string slurmBakeStatus(const bake::BakeConfig& cfg) {
  const fs::path dir = slurmDir(cfg);
  const fs::path subFile = dir / "submission.json";
  if (!fs::exists(subFile))
    throw Error("bake '" + cfg.name + "': nothing was submitted from " + dir.string() +
                " (no submission.json); submit with `swish bake CONFIG --slurm`");
  const nlohmann::json sub = readJsonFile(subFile);
  const PoseList list = readPoseList(dir / "poses.bin");
  std::string out;
  auto line = [&](const std::string& l) { out += l + "\n"; };
  const std::string fp = sub.value("pose_list", std::string());
  line("bake '" + cfg.name + "': submitted " + sub.value("submitted", std::string("?")) + " from " +
       sub.value("submitted_from", std::string("?")) +
       (sub.value("dry_run", false) ? " (dry run: nothing queued)" : "") + ", pose list " + fp);
  if (fingerprintHex(list.fingerprint) != fp)
    line("warning: " + (dir / "poses.bin").string() + " holds the pose list " + fingerprintHex(list.fingerprint) +
         ", not the submission's");

  const size_t n = list.poses.size();
  const size_t shardSize = std::max<size_t>(1, sub.value("shard_size", size_t(1)));
  const int cpus = std::max(1, sub.value("cpus_per_task", 1));
  const PoseFileState files = scanPoseFiles(cfg.simulationDir(), list.poseFingerprints);
  size_t done = 0, failed = 0;
  for (uint8_t st : files.state) done += st != 0, failed += st == 2;

  std::string queueError;
  const auto queue = queueOf(submittedJobs(sub), &queueError);
  const nlohmann::json jobs = sub.value("jobs", nlohmann::json::object());
  auto jobId = [&](const char* k) { return jobs.contains(k) && jobs[k].is_string() ? jobs[k].get<std::string>() : ""; };
  const std::string arrayId = jobId("part1");
  std::set<size_t> running, pending;
  std::map<std::string, QueueEntry> single;
  if (queue)
    for (const QueueEntry& e : *queue) {
      if (!arrayId.empty() && e.id.rfind(arrayId + "_", 0) == 0) {
        const std::string k = e.id.substr(arrayId.size() + 1);
        if (k.empty() || k.find_first_not_of("0123456789") != std::string::npos) continue;
        (e.state == "RUNNING" || e.state == "COMPLETING" ? running : pending).insert(std::stoul(k));
      } else {
        single[e.id] = e;
      }
    }
  size_t inFlight = 0;
  std::string runningList;
  for (size_t k : running) {
    size_t left = 0;
    for (size_t i = k * shardSize; i < std::min(n, (k + 1) * shardSize); ++i) left += files.state[i] == 0;
    inFlight += std::min<size_t>(left, size_t(cpus));
    runningList += (runningList.empty() ? "" : ", ") + std::to_string(k);
  }
  const size_t waiting = n - done - inFlight;
  {
    char l[400];
    std::snprintf(l, sizeof l, "part 1: %zu of %zu poses done (%zu failed, left out), %zu running, %zu waiting", done,
                  n, failed, inFlight, waiting);
    line(l);
  }
  line("  job " + (arrayId.empty() ? std::string("none (every pose was simulated before the submission)") : arrayId) +
       ": " + std::to_string(sub.value("shards", size_t(0))) + " shards of " + std::to_string(shardSize) + " poses, " +
       std::to_string(cpus) + " cpus per task; array tasks running " + std::to_string(running.size()) +
       (runningList.empty() ? "" : " (shards " + runningList + ")") + ", pending " + std::to_string(pending.size()));
  if (done < n) {
    const double spp = files.seconds.size() >= 3 ? median(files.seconds) : sub.value("seconds_per_pose", 0.0);
    const size_t tasks = std::max<size_t>(1, running.size());
    const double left = std::ceil(double(n - done) / double(tasks * size_t(cpus))) * spp;
    char l[300];
    std::snprintf(l, sizeof l, "  about %s left at %.2f s per pose (%s) with %zu task%s of %d cpus at once",
                  duration(left).c_str(), spp,
                  files.seconds.size() >= 3 ? "median so far" : "the submission's estimate", tasks,
                  tasks == 1 ? "" : "s", cpus);
    line(l);
  }
  for (size_t k : running) {
    try {
      const nlohmann::json j = readJsonFile(shardFile(dir, k));
      line("  shard " + std::to_string(k) + ": " + std::to_string(j.value("done", 0)) + "/" +
           std::to_string(j.value("count", 0)) + " on " + j.value("host", std::string("?")) + ", restart " +
           std::to_string(j.value("restart", 0)) + ", updated " + j.value("updated", std::string("?")));
    } catch (const Error&) {
      line("  shard " + std::to_string(k) + ": starting");
    }
  }

  const auto subTime = fs::last_write_time(subFile);
  auto newer = [&](const fs::path& f) {
    std::error_code ec;
    return fs::exists(f, ec) && fs::last_write_time(f, ec) >= subTime;
  };
  auto stageLine = [&](const std::string& what, const std::string& id, const fs::path& output) {
    if (id.empty()) return line(what + ": not submitted (dry run)");
    if (auto it = single.find(id); it != single.end())
      return line(what + ": job " + id + " " + it->second.state +
                  (it->second.reason.empty() || it->second.reason == "None" ? "" : " (" + it->second.reason + ")"));
    if (!queue) return line(what + ": job " + id + ": queue not readable");
    if (newer(output)) return line(what + ": job " + id + " done: " + output.string());
    line(what + ": job " + id + " is not in the queue and " + output.string() +
         " was not written: it failed or was cancelled (see " + (dir / "logs").string() + ")");
  };
  stageLine("dataset", jobId("dataset"), cfg.dataset / "manifest.json");
  stageLine("part 2", jobId("part2"), cfg.modelPath());
  if (!queue) line("queue: " + queueError + " (progress above is from the files only)");
  return out;
}

}  // namespace swish::cluster
