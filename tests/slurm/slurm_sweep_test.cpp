// The Slurm executor of `stereobench sweep run`: the job array script, the missing-Slurm error,
// and sweeps run through a real single-node Slurm (munged, slurmctld, slurmd from Debian) that
// each cluster test starts in a private folder with tests/slurm/start_slurm.sh and stops after.
// A cluster that cannot start fails the test with the daemon logs; it never skips.
#include <gtest/gtest.h>

#include <stdlib.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/error.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/results_file.hpp"
#include "validation/slurm.hpp"
#include "validation/sweep.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using test::run_shell;
using test::quoted;
using nlohmann::json;

/// Four cells (interaxial 40, 64, 100, 140 mm) of the box in front of a wall at 64x36, every
/// registered pipeline, one timed repetition.
constexpr const char* kFourCells = R"([sweep]
name = "slurm-four"
scenes = ["box-wall"]
pipelines = "all"
interaxial_m = [0.04, 0.064, 0.1, 0.14]
resolutions = ["64x36"]

[timing]
repetitions = 1
warmup = 0
)";

/// Two cells, for the failure and resubmission test.
constexpr const char* kTwoCells = R"([sweep]
name = "slurm-two"
scenes = ["box-wall"]
pipelines = ["plain-rt", "repro-rt"]
interaxial_m = [0.04, 0.1]
resolutions = ["64x36"]

[timing]
repetitions = 1
warmup = 0
)";

/// What must agree between the local and the Slurm run of a cell: everything measured, not time.
json measured(const json& cell) {
  json out = {{"cell", cell["cell"]}, {"rig", cell["rig"]}, {"baseline", cell["baseline"]}};
  for (const auto& [name, p] : cell["pipelines"].items()) {
    const json& v = p["validation"];
    out[name] = {{"metrics", v["metrics"]}, {"regions", v["regions"]}, {"holes", v["holes"]},
                 {"counters", v["counters"]}, {"options", v["options"]}};
  }
  return out;
}

std::map<std::string, json> measured_by_id(const fs::path& file) {
  std::map<std::string, json> out;
  for (const json& c : validation::read_results(file).cells) out[c["cell_id"].get<std::string>()] = measured(c);
  return out;
}

/// A private Slurm cluster for one test: started in a fresh folder under /tmp (the munge and
/// slurmd sockets need short paths), SLURM_CONF pointing at it while it runs, stopped at the end.
/// Its folder is kept, with the daemon logs, when the test failed.
class SlurmCluster : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = "/tmp/sb-slurm-XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
    const auto start = std::chrono::steady_clock::now();
    const test::CliRun r = run_shell("bash " + quoted(fs::path(SB_SOURCE_DIR) / "tests/slurm/start_slurm.sh") + " " +
                                     quoted(dir_));
    start_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(r.code, 0) << "the single-node Slurm cluster did not start (folder " << dir_
                         << " kept); start_slurm.sh said:\n"
                         << r.out;
    ::setenv("SLURM_CONF", (dir_ / "slurm.conf").c_str(), 1);
    std::printf("slurm cluster up in %.1f s (%s)\n", start_s_, dir_.c_str());
  }

  void TearDown() override {
    if (dir_.empty()) return;
    const test::CliRun r =
        run_shell("bash " + quoted(fs::path(SB_SOURCE_DIR) / "tests/slurm/stop_slurm.sh") + " " + quoted(dir_));
    EXPECT_EQ(r.code, 0) << r.out;
    ::unsetenv("SLURM_CONF");
    std::error_code ec;
    if (!HasFailure())
      fs::remove_all(dir_, ec);
    else
      std::printf("slurm cluster folder kept: %s\n", dir_.c_str());
  }

  fs::path dir_;
  double start_s_ = 0.0;
};

// ---- without a cluster

TEST(SlurmScript, JobArrayRunsOneShardPerTask) {
  const validation::SweepDefinition d = validation::parse_sweep(kFourCells, "/defs/four.toml");
  validation::SlurmSweepOptions o;
  o.stereobench = "/opt/sb/bin/stereobench";
  o.out_dir = "/data/sweeps/four";
  o.workdir = "/data";
  o.shards = 3;
  o.partition = "debug";
  o.time_limit = "00:10:00";
  o.run_args = {"--jobs", "1", "--cache", "", "--scenes-dir", "/data/it's scenes"};
  const std::string s = validation::sbatch_script(d, o);
  for (const char* line : {"#!/bin/bash\n", "#SBATCH --array=0-2\n", "#SBATCH --job-name=sb-sweep-slurm-four\n",
                           "#SBATCH --output=\"/data/sweeps/four/slurm/task-%a.out\"\n",
                           "#SBATCH --error=\"/data/sweeps/four/slurm/task-%a.err\"\n", "#SBATCH --chdir=\"/data\"\n",
                           "#SBATCH --partition=debug\n", "#SBATCH --time=00:10:00\n"})
    EXPECT_NE(s.find(line), std::string::npos) << line << "\n" << s;
  EXPECT_NE(s.find("'/opt/sb/bin/stereobench' sweep run '/defs/four.toml' --out '/data/sweeps/four'"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("--shard \"$task/3\" --results \"$slurm_dir/results-$task.jsonl\""), std::string::npos) << s;
  // Forwarded options keep their words, empty ones and quotes included.
  EXPECT_NE(s.find("'--cache' '' '--scenes-dir' '/data/it'\\''s scenes'"), std::string::npos) << s;
  // Directives come before the first command (sbatch stops reading them there).
  EXPECT_LT(s.rfind("#SBATCH"), s.find("set -u"));

  // Run as a shell script, with a stand-in for stereobench that prints its arguments and fails:
  // task 2 of 3 gets its shard, results file and the CPUs Slurm allocated, and its exit code is
  // both written to task-2.status and returned.
  test::ScratchDir dir;
  o.out_dir = dir.path();
  std::string script = validation::sbatch_script(d, o);
  const std::string exe = "'/opt/sb/bin/stereobench'";
  script.replace(script.find(exe), exe.size(), "sh -c 'printf \"%s\\n\" \"$@\"; exit 7' stand-in");
  std::ofstream(dir / "script.sh") << script;
  fs::create_directories(dir / "slurm");
  const test::CliRun r = run_shell("cd " + quoted(dir.path()) + " && SLURM_ARRAY_TASK_ID=2 SLURM_CPUS_ON_NODE=3 bash " +
                                   quoted(dir / "script.sh") + "; echo rc=$?");
  EXPECT_NE(r.out.find("sweep\nrun\n/defs/four.toml\n--out\n" + dir.path().string() + "\n--shard\n2/3\n--results\n" +
                       (dir / "slurm" / "results-2.jsonl").string() + "\n--threads\n3\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("--cache\n\n--scenes-dir\n/data/it's scenes\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rc=7"), std::string::npos) << r.out;
  EXPECT_EQ(test::read_text(dir / "slurm" / "task-2.status"), "7\n");
  // Outside a job array it refuses to run.
  const test::CliRun outside = run_shell("env -u SLURM_ARRAY_TASK_ID bash " + quoted(dir / "script.sh"));
  EXPECT_NE(outside.code, 0);
  EXPECT_NE(outside.out.find("runs as a task of a Slurm job array"), std::string::npos) << outside.out;
}

TEST(SlurmScript, BadOptionsAreInputErrors) {
  const validation::SweepDefinition d = validation::parse_sweep(kFourCells, "/defs/four.toml");
  validation::SlurmSweepOptions o;
  o.stereobench = "/opt/stereobench";
  o.out_dir = "/data/my sweeps";  // a blank is carried in double quotes
  o.workdir = "/data/work dir";
  o.shards = 2;
  const std::string script = validation::sbatch_script(d, o);
  EXPECT_NE(script.find("#SBATCH --output=\"/data/my sweeps/slurm/task-%a.out\"\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --chdir=\"/data/work dir\"\n"), std::string::npos) << script;
  // A double quote, a backslash, a '%' or a newline cannot be carried.
  for (const char* bad : {"/data/my \"sweeps\"", "/data/a\\b", "/data/100%", "/data/a\nb"}) {
    o.out_dir = bad;
    EXPECT_THROW((void)validation::sbatch_script(d, o), InputError) << bad;
  }
  o.out_dir = "/data/sweeps";
  o.workdir = "/data/a\nb";
  EXPECT_THROW((void)validation::sbatch_script(d, o), InputError);
  o.workdir = "/data";
  // A newline in the definition's path stays inside the script's comment.
  const validation::SweepDefinition newline = validation::parse_sweep(kFourCells, "/defs/four\necho INJECTED.toml");
  const std::string commented = validation::sbatch_script(newline, o);
  EXPECT_NE(commented.find("(/defs/four\\necho INJECTED.toml)"), std::string::npos) << commented;
  // Every line up to the first command is a comment or a directive: sbatch reads all directives.
  std::istringstream lines(commented);
  for (std::string line; std::getline(lines, line) && line != "set -u";)
    EXPECT_EQ(line.rfind('#', 0), 0u) << line << "\n" << commented;
  o.out_dir = "/data/sweeps";
  o.shards = 0;
  EXPECT_THROW((void)validation::sbatch_script(d, o), InputError);
  o.shards = 2;
  o.partition = "debug;rm";
  EXPECT_THROW((void)validation::sbatch_script(d, o), InputError);
  o.partition.clear();
  // Extra sbatch options are directives after the script's own (which they override as on the
  // command line), a value with blanks in double quotes; what a directive cannot carry is refused.
  o.sbatch_args = {"--mem=8G", "--hold", "-c4", "--comment=two words", "--job-name=it's", "--comment=run#2"};
  const std::string extra = validation::sbatch_script(d, o);
  const size_t chdir = extra.find("#SBATCH --chdir=");
  const size_t mem = extra.find(
      "#SBATCH --mem=8G\n#SBATCH --hold\n#SBATCH -c4\n#SBATCH --comment=\"two words\"\n#SBATCH --job-name=\"it's\"\n"
      "#SBATCH --comment=\"run#2\"\n");
  EXPECT_NE(mem, std::string::npos) << extra;
  EXPECT_LT(chdir, mem) << extra;
  for (const char* bad :
       {"mem=8G", "", "--comment=a\"b", "--comment=a\\b", "--comment=a\nb", "-c 4", "--mem 8G", "-J#1", "--x'y=1"}) {
    o.sbatch_args = {bad};
    EXPECT_THROW((void)validation::sbatch_script(d, o), InputError) << bad;
  }
  // What the script sets itself and the merge relies on: an array of one task per shard, with
  // task I's logs in its files, in the working directory. sbatch takes a long option by any
  // unambiguous start, and options of other names starting alike stay allowed.
  for (const char* owned : {"--array=0-3", "--array=0-1%1", "-a0-3", "--arr=0-3", "--output=x.out", "-ox.out",
                            "--out=x", "--error=x.err", "-ex", "--chdir=/tmp", "-D/tmp", "--ntasks=2", "-n2"}) {
    o.sbatch_args = {owned};
    try {
      (void)validation::sbatch_script(d, o);
      ADD_FAILURE() << owned << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("which the sweep's job script sets itself"), std::string::npos) << e.what();
    }
  }
  o.sbatch_args = {"--ntasks-per-node=1", "--nodes=1", "-N1", "--exclusive", "-A", "--export=NONE"};
  EXPECT_NO_THROW((void)validation::sbatch_script(d, o));
  // A throttle is the executor's own option: the array's %M.
  o.sbatch_args.clear();
  o.max_running = 1;
  EXPECT_NE(validation::sbatch_script(d, o).find("#SBATCH --array=0-1%1\n"), std::string::npos);
  o.max_running = 0;
  for (const char* ok : {"10", "10:30", "01:30:00", "2-12", "2-12:30", "2-12:30:00", "infinite"})
    EXPECT_NO_THROW(validation::check_slurm_time_limit(ok)) << ok;
  for (const char* bad : {"", "1h", "01:30:00:00", "-5", "1-", "abc", "1:99:99", "10:60", "2-24", "2-12:60"})
    EXPECT_THROW(validation::check_slurm_time_limit(bad), InputError) << bad;
}

TEST(SlurmExecutor, MissingSbatchIsAToolError) {
  test::ScratchDir dir;
  std::ofstream(dir / "four.toml") << kFourCells;
  // PATH without the Slurm client commands: exit 4, naming the install script and the cluster.
  const test::CliRun r = run_shell("env PATH=" + quoted(dir.path()) + " " + std::string(SB_CLI_PATH) + " sweep run " +
                                   quoted(dir / "four.toml") + " --out " + quoted(dir / "out") + " --scenes-dir " +
                                   quoted(dir / "scenes") + " --executor slurm --shards 2");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("ci/install-deps.sh slurm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Slurm cluster"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'sbatch' not found"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_FALSE(fs::exists(dir / "scenes"));
}

TEST(SlurmExecutor, OptionsOfTheWrongExecutorAreUsageErrors) {
  test::ScratchDir dir;
  std::ofstream(dir / "four.toml") << kFourCells;
  const std::string base = "sweep run " + quoted(dir / "four.toml") + " --out " + quoted(dir / "out") +
                           " --scenes-dir " + quoted(dir / "scenes");
  const test::CliRun shards = test::run_cli(base + " --shards 2");
  EXPECT_EQ(shards.code, 3) << shards.out;
  EXPECT_NE(shards.out.find("--shards"), std::string::npos) << shards.out;
  const test::CliRun shard = test::run_cli(base + " --executor slurm --shard 1/2");
  EXPECT_EQ(shard.code, 3) << shard.out;
  EXPECT_NE(shard.out.find("--shards N"), std::string::npos) << shard.out;
  const test::CliRun too_many = test::run_cli(base + " --executor slurm --shards 5");
  EXPECT_EQ(too_many.code, 3) << too_many.out;
  EXPECT_NE(too_many.out.find("more than the 4 cells"), std::string::npos) << too_many.out;
  const test::CliRun time = test::run_cli(base + " --executor slurm --time-limit 1h");
  EXPECT_EQ(time.code, 3) << time.out;
  EXPECT_NE(time.out.find("--time-limit '1h'"), std::string::npos) << time.out;
  // Options are checked before anything is generated or submitted.
  EXPECT_FALSE(fs::exists(dir / "scenes"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// ---- against a real single-node cluster

TEST_F(SlurmCluster, SweepThroughSlurmEqualsTheLocalExecutor) {
  test::ScratchDir dir;
  std::ofstream(dir / "four.toml") << kFourCells;
  ASSERT_EQ(test::run_cli("scenes generate box-wall --out " + quoted(dir / "scenes")).code, 0);
  const std::string common = " --scenes-dir " + quoted(dir / "scenes") + " --cache ''";

  auto start = std::chrono::steady_clock::now();
  const test::CliRun local =
      test::run_cli("sweep run " + quoted(dir / "four.toml") + " --out " + quoted(dir / "local") + common + " --threads 1");
  const double local_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(local.code, 0) << local.out;

  start = std::chrono::steady_clock::now();
  // A blank in the output folder's path reaches sbatch's directives (in quotes) and the task's command.
  const fs::path out = dir / "slurm out";
  const test::CliRun slurm = test::run_cli("sweep run " + quoted(dir / "four.toml") + " --out " + quoted(out) + common +
                                           " --executor slurm --shards 2 --time-limit 00:05:00 --wait");
  const double slurm_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("local executor %.1f s, slurm executor (2 tasks, submit to merge) %.1f s\n", local_s, slurm_s);
  ASSERT_EQ(slurm.code, 0) << slurm.out << "\nslurmctld log:\n"
                           << test::read_text(dir_ / "log" / "slurmctld.log") << "\nslurmd log:\n"
                           << test::read_text(dir_ / "log" / "slurmd.log");
  EXPECT_NE(slurm.out.find("submitted to Slurm as job "), std::string::npos) << slurm.out;
  EXPECT_NE(slurm.out.find("2/2 tasks ended"), std::string::npos) << slurm.out;

  // The job array: its script, one results file and log per task, each holding its shard's cells.
  const fs::path sd = out / "slurm";
  EXPECT_NE(test::read_text(sd / "sweep.sbatch").find("#SBATCH --array=0-1\n"), std::string::npos);
  const json submission = json::parse(test::read_text(sd / "submission.json"));
  EXPECT_EQ(submission["shards"], 2);
  EXPECT_NE(slurm.out.find("as job " + submission["job_id"].get<std::string>() + ":"), std::string::npos);
  for (size_t task = 0; task < 2; ++task) {
    const std::vector<json> cells = validation::read_results(sd / ("results-" + std::to_string(task) + ".jsonl")).cells;
    ASSERT_EQ(cells.size(), 2u) << "task " << task;
    for (const json& c : cells) EXPECT_EQ(c["cell_index"].get<size_t>() % 2, task) << c["cell_id"];
    EXPECT_EQ(test::read_text(sd / ("task-" + std::to_string(task) + ".status")), "0\n");
    // The task's own output, written by Slurm into the file of its array index.
    EXPECT_NE(test::read_text(sd / ("task-" + std::to_string(task) + ".out")).find("shard " + std::to_string(task) + "/2"),
              std::string::npos);
  }

  // The merge equals the local run: the same cells, and per (cell, pipeline) the same metrics.
  const std::vector<json> merged = validation::read_results(out / "results.jsonl").cells;
  ASSERT_EQ(merged.size(), 4u);
  for (size_t i = 0; i < merged.size(); ++i) EXPECT_EQ(merged[i]["cell_index"], i);
  const auto a = measured_by_id(dir / "local" / "results.jsonl");
  const auto b = measured_by_id(out / "results.jsonl");
  ASSERT_EQ(a.size(), 4u);
  std::set<std::string> ids_a, ids_b;
  for (const auto& [id, m] : a) ids_a.insert(id);
  for (const auto& [id, m] : b) ids_b.insert(id);
  EXPECT_EQ(ids_a, ids_b);
  for (const auto& [id, m] : a) {
    ASSERT_TRUE(b.count(id)) << id;
    EXPECT_GE(m.size(), 5u) << id;  // cell, rig, baseline and at least two pipelines
    for (const auto& [key, value] : m.items()) EXPECT_EQ(b.at(id)[key], value) << id << " " << key;
  }
  // The images the lines name exist beside the merged file: the cell's, and each pipeline's
  // validation record's (the shards wrote them relative to their own files).
  for (const auto& [name, files] : merged.front()["images"]["pipelines"].items())
    for (const auto& [kind, path] : files.items())
      EXPECT_TRUE(fs::exists(out / path.get<std::string>())) << name << " " << kind;
  for (const auto& [name, record] : merged.front()["pipelines"].items())
    for (const auto& [kind, path] : record["validation"]["images"].items())
      if (path.is_string()) {
        EXPECT_TRUE(fs::exists(out / path.get<std::string>())) << name << " " << kind << " " << path;
      }
}

TEST_F(SlurmCluster, FailedTasksAreReportedAndResubmissionContinues) {
  test::ScratchDir dir;
  std::ofstream(dir / "two.toml") << kTwoCells;
  ASSERT_EQ(test::run_cli("scenes generate box-wall --out " + quoted(dir / "scenes")).code, 0);
  const std::string run = "sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") +
                          " --scenes-dir " + quoted(dir / "scenes") + " --cache '' --executor slurm --shards 2 --wait";
  // Task 1 finds a results file it cannot read and fails with a usage error.
  const fs::path sd = dir / "out" / "slurm";
  fs::create_directories(sd);
  std::ofstream(sd / "results-1.jsonl") << "not json\n";
  const test::CliRun failed = test::run_cli(run);
  EXPECT_EQ(failed.code, 3) << failed.out;
  EXPECT_NE(failed.out.find("1 of the 2 tasks of Slurm job"), std::string::npos) << failed.out;
  EXPECT_NE(failed.out.find("task 1 of job"), std::string::npos) << failed.out;
  EXPECT_NE(failed.out.find("exited with code 3"), std::string::npos) << failed.out;
  // The tail of the task's stderr names the bad file.
  EXPECT_NE(failed.out.find("last lines of " + (sd / "task-1.err").string()), std::string::npos) << failed.out;
  EXPECT_NE(failed.out.find((sd / "results-1.jsonl").string() + ":1"), std::string::npos) << failed.out;
  EXPECT_EQ(failed.out.find("task 0 of job"), std::string::npos) << failed.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "results.jsonl"));
  EXPECT_EQ(validation::read_results(sd / "results-0.jsonl").cells.size(), 1u);

  // The local executor does not run into a folder submitted to Slurm (it used to run every cell
  // beside a queued array) ...
  const test::CliRun local = test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") +
                                           " --scenes-dir " + quoted(dir / "scenes") + " --cache ''");
  EXPECT_EQ(local.code, 3) << local.out;
  EXPECT_NE(local.out.find("was submitted to Slurm as job"), std::string::npos) << local.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "results.jsonl"));
  // ... and a results file put there otherwise (by hand, or by an older version's local run) is
  // not the merge's to replace (it was, once any submission had been made there).
  fs::copy_file(sd / "results-0.jsonl", dir / "out" / "results.jsonl");
  const std::string local_results = test::read_text(dir / "out" / "results.jsonl");
  const test::CliRun over = test::run_cli(run);
  EXPECT_EQ(over.code, 3) << over.out;
  EXPECT_NE(over.out.find("is not the file the slurm executor merged there"), std::string::npos) << over.out;
  EXPECT_EQ(test::read_text(dir / "out" / "results.jsonl"), local_results);
  fs::remove(dir / "out" / "results.jsonl");

  // Fixed and submitted again: task 0 has nothing left, task 1 runs its cell, the merge is complete.
  fs::remove(sd / "results-1.jsonl");
  const std::string line0 = test::read_text(sd / "results-0.jsonl");
  const test::CliRun again = test::run_cli(run);
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_EQ(test::read_text(sd / "results-0.jsonl"), line0);
  EXPECT_NE(test::read_text(sd / "task-0.out").find("1 finished already, 0 to run"), std::string::npos);
  EXPECT_EQ(validation::read_results(dir / "out" / "results.jsonl").cells.size(), 2u);
  // The file its own merge wrote is the merge's to write again.
  const std::string merged = test::read_text(dir / "out" / "results.jsonl");
  const test::CliRun remerge = test::run_cli(run);
  ASSERT_EQ(remerge.code, 0) << remerge.out;
  EXPECT_EQ(validation::read_results(dir / "out" / "results.jsonl").cells.size(), 2u);
  // ... also after a resubmission that failed (the new submission's record keeps what was merged),
  // and after the shards were merged by hand with `sweep collect`, as the executor advises when it
  // does not wait.
  const std::string good_shard = test::read_text(sd / "results-1.jsonl");
  std::ofstream(sd / "results-1.jsonl", std::ios::trunc) << "not json\n";
  EXPECT_EQ(test::run_cli(run).code, 3);
  std::ofstream(sd / "results-1.jsonl", std::ios::trunc) << good_shard;
  const test::CliRun after_failure = test::run_cli(run);
  EXPECT_EQ(after_failure.code, 0) << after_failure.out;
  const test::CliRun collected = test::run_cli("sweep collect " + quoted(dir / "out" / "results.jsonl") + " " +
                                               quoted(sd / "results-0.jsonl") + " " + quoted(sd / "results-1.jsonl"));
  ASSERT_EQ(collected.code, 0) << collected.out;
  const test::CliRun after_collect = test::run_cli(run);
  EXPECT_EQ(after_collect.code, 0) << after_collect.out;

  // A different sharding of the same folder is refused (its cells would be run twice).
  const test::CliRun reshard = test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") +
                                             " --scenes-dir " + quoted(dir / "scenes") + " --executor slurm --shards 1");
  EXPECT_EQ(reshard.code, 3) << reshard.out;
  EXPECT_NE(reshard.out.find("--shards 2"), std::string::npos) << reshard.out;

  // A task cancelled before it ran: no exit code, reported with its Slurm state.
  const test::CliRun held = test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "held") +
                                          " --scenes-dir " + quoted(dir / "scenes") +
                                          " --executor slurm --shards 2 --sbatch-arg=--hold");
  ASSERT_EQ(held.code, 0) << held.out;
  EXPECT_NE(held.out.find("run this command again with --wait"), std::string::npos) << held.out;
  const fs::path hd = dir / "held" / "slurm";
  const std::string job = json::parse(test::read_text(hd / "submission.json"))["job_id"];
  const test::CliRun busy = test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "held") +
                                          " --scenes-dir " + quoted(dir / "scenes") + " --executor slurm --shards 2");
  EXPECT_EQ(busy.code, 3) << busy.out;
  EXPECT_NE(busy.out.find("job " + job + " of this sweep"), std::string::npos) << busy.out;
  ASSERT_EQ(run_shell("scancel " + job).code, 0);
  validation::SlurmSubmission sub;
  sub.job_id = job;
  sub.shards = 2;
  sub.layout = validation::slurm_layout(dir / "held");
  const std::vector<validation::SlurmTaskOutcome> outcomes =
      validation::wait_for_array(sub, std::chrono::milliseconds(200));
  ASSERT_EQ(outcomes.size(), 2u);
  for (const auto& o : outcomes) {
    EXPECT_FALSE(o.ok());
    EXPECT_EQ(o.state, "CANCELLED") << o.detail;
    EXPECT_FALSE(o.exit_code.has_value());
    EXPECT_NE(o.detail.find("without writing its exit code"), std::string::npos) << o.detail;
  }
  EXPECT_NE(validation::describe_failed_tasks(sub, outcomes).find("task 1 of job " + job + " (CANCELLED)"),
            std::string::npos);
}

}  // namespace
}  // namespace sb
