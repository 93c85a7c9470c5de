// `animorder batch` end to end: shards run in parallel give the same files and summary as one
// run, a killed run resumes without redoing finished items, a broken item fails alone, a changed
// option re-runs only the item it belongs to, and every output is checked before any work. The
// references are independent of batch: `animorder optimize` run alone with the same options,
// `inspect` for the input order's ACMR, `evaluate` for the optimised order's OVR.
#include <gtest/gtest.h>

#include "support/files.h"
#include "support/require.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
namespace test = animorder::test;

namespace {

// Small settings so every item takes a fraction of a second on the bundled character.
const std::string kFast = "-k 2 --views 12 --resolution 32 --max-iterations 2";
const std::string kEval = " --eval-views 1 --eval-resolution 32";

class Batch : public test::ScratchFolderTest {
protected:
    Batch() : ScratchFolderTest("animorder-batch") {}
    void SetUp() override {
        ScratchFolderTest::SetUp();
        fs::create_directories(path("out"));
    }
    test::Outcome run(const std::string& args) {
        return test::run_captured(std::string(ANIMORDER_EXE) + " " + args, dir_);
    }
    test::Outcome run_shell(const std::string& command) { return test::run_captured(command, dir_); }
    std::string manifest() const { return path("m.json").string(); }
    void write(const std::string& name, const std::string& text) {
        std::ofstream(path(name), std::ios::binary) << text;
    }

    // Every regular file under out/ (name → bytes), temporaries included.
    std::map<std::string, std::string> outputs() const {
        std::map<std::string, std::string> files;
        for (const auto& e : fs::directory_iterator(path("out")))
            files[e.path().filename().string()] = test::slurp(e.path());
        return files;
    }
};

// Starts `argv` (argv[0] the executable) in `folder`, its stdout and stderr into `log`, without
// waiting for it: its pid, or -1 when it cannot be started (the child's failure to open the log or
// run the program shows as exit code 126 or 127).
pid_t start_in(const fs::path& folder, const std::vector<std::string>& argv, const fs::path& log) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const std::string where = folder.string(), log_path = log.string();
    const pid_t child = fork();
    if (child != 0) return child;
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || ::chdir(where.c_str()) != 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0) _exit(126);
    ::execv(args[0], args.data());
    _exit(127);
}

// Five items over the bundled character: single per clip, joint, two static methods.
const char* kFiveItems = R"({"items": [
  {"name": "walk-single", "clips": ["walk"], "options": "-k 2 --views 12 --resolution 32 --max-iterations 2", "output": "out/walk"},
  {"name": "sander", "method": "static-sander07", "options": {"lambda": 3}, "output": "out/sander"},
  {"name": "joint", "method": "joint", "options": ["-k", "2", "--views", "12", "--resolution", "32", "--max-iterations", "2"], "output": "out/joint"},
  {"name": "wave-seed2", "clips": "wave", "options": "-k 2 --views 12 --resolution 32 --max-iterations 2 --seed 2", "output": "out/wave"},
  {"name": "original", "method": "original", "output": "out/original"}
]})";

}  // namespace

TEST_F(Batch, ThreeParallelShardsGiveTheFilesAndSummaryOfOneRun) {
    write("m.json", kFiveItems);
    const test::Outcome one = run("batch -q --no-timings" + kEval + " " + manifest());
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const std::map<std::string, std::string> single_run = outputs();
    const std::string summary_json = test::slurp_existing(path("m.summary.json")),
                      summary_md = test::slurp_existing(path("m.summary.md"));
    ASSERT_EQ(single_run.size(), 5u * 3u);  // sidecar, its description and the item report each
    for (const auto& [name, bytes] : single_run) EXPECT_NE(name[0], '.') << name << ": a temporary was left";

    // Each item's files are exactly what `animorder optimize` writes alone with the same options.
    ASSERT_EQ(run("optimize -q --clip walk " + kFast + " -o " + path("alone").string()).exit_code, 0);
    EXPECT_EQ(test::slurp_existing(path("alone.animorder.bin")), single_run.at("walk.animorder.bin"));
    ASSERT_EQ(run("optimize -q --method joint " + kFast + " -o " + path("alone-joint").string()).exit_code, 0);
    EXPECT_EQ(test::slurp_existing(path("alone-joint.animorder.bin")), single_run.at("joint.animorder.bin"));

    // The summary's numbers: the input order's ACMR from inspect, the triangles, the clips, the
    // buffers of measured, the default (k per clip), and joint (k), the index bytes those buffers add.
    const nlohmann::json inspect = nlohmann::json::parse(run("inspect --json -q").out);
    const nlohmann::json s = nlohmann::json::parse(summary_json);
    ASSERT_EQ(s["items"].size(), 5u);
    EXPECT_EQ(s["ok"], 5);
    const size_t triangles = inspect["triangles"].get<size_t>();
    for (const auto& row : s["items"]) {
        EXPECT_EQ(row["status"], "ok") << row.dump();
        EXPECT_EQ(row["triangles"], triangles);
        EXPECT_DOUBLE_EQ(row["acmr_before"].get<double>(), inspect["input_order"]["acmr"].get<double>());
        EXPECT_TRUE(row["time_s"].is_null());  // --no-timings
        EXPECT_EQ(row["index_bytes_added"].get<size_t>(), (row["buffers"].get<size_t>() - 1) * triangles * 12);
    }
    // --no-timings takes the peak memory out of the item reports too (it differs run to run).
    const nlohmann::json item = nlohmann::json::parse(single_run.at("walk.animorder.report.json"));
    ASSERT_TRUE(item["methods"][0].contains("peak_rss_bytes"));
    EXPECT_TRUE(item["methods"][0]["peak_rss_bytes"].is_null());
    EXPECT_EQ(s["items"][0]["clips"], 1);
    EXPECT_EQ(s["items"][0]["buffers"], 2);
    EXPECT_EQ(s["items"][2]["clips"], 2);
    EXPECT_EQ(s["items"][2]["buffers"], 2);
    EXPECT_EQ(s["items"][4]["buffers"], 1);
    EXPECT_NE(summary_md.find("| wave-seed2 | measured | " + std::to_string(triangles) + " | 1 |"), std::string::npos)
        << summary_md;

    // Again as three shards at once, then the merge: the same bytes.
    for (const auto& e : fs::directory_iterator(path("out"))) fs::remove(e.path());
    fs::remove(path("m.summary.json"));
    fs::remove(path("m.summary.md"));
    // Each shard a process of its own, all three started before any is waited for, and each one's
    // exit status checked (a shell's `A & B & C & wait` exits 0 whatever they do).
    pid_t shards[3];
    for (int i = 0; i < 3; ++i) {
        std::vector<std::string> args = {ANIMORDER_EXE, "batch", "-q", "--no-timings"};
        std::istringstream eval(kEval);
        for (std::string word; eval >> word;) args.push_back(word);
        args.insert(args.end(), {"--shard", std::to_string(i) + "/3", manifest()});
        shards[i] = start_in(dir_, args, path("shard" + std::to_string(i) + ".txt"));
        ASSERT_GT(shards[i], 0) << "cannot start shard " << i;
    }
    int statuses[3] = {-1, -1, -1};
    for (int i = 0; i < 3; ++i) EXPECT_EQ(waitpid(shards[i], &statuses[i], 0), shards[i]) << "shard " << i;
    for (int i = 0; i < 3; ++i) {
        const std::string log = test::slurp(path("shard" + std::to_string(i) + ".txt"));
        ASSERT_TRUE(WIFEXITED(statuses[i])) << "shard " << i << " did not exit: " << log;
        ASSERT_EQ(WEXITSTATUS(statuses[i]), 0) << "shard " << i << ": " << log;
    }
    EXPECT_NE(test::slurp(path("shard0.txt")).find("shard 0/3: 2 items: 2 done"), std::string::npos)
        << test::slurp(path("shard0.txt"));
    EXPECT_NE(test::slurp(path("shard2.txt")).find("shard 2/3: 1 items: 1 done"), std::string::npos)
        << test::slurp(path("shard2.txt"));
    EXPECT_FALSE(fs::exists(path("m.summary.json")));  // a shard leaves the summary to the merge
    const test::Outcome merge = run("batch -q --merge --no-timings" + kEval + " " + manifest());
    ASSERT_EQ(merge.exit_code, 0) << merge.err;
    EXPECT_EQ(outputs(), single_run);
    EXPECT_EQ(test::slurp_existing(path("m.summary.json")), summary_json);
    EXPECT_EQ(test::slurp_existing(path("m.summary.md")), summary_md);

    // The shard index from a farm's environment.
    const test::Outcome k8s = test::run_captured("env JOB_COMPLETION_INDEX=1 " + std::string(ANIMORDER_EXE) +
                                                     " batch -q --no-timings" + kEval + " --shard env/3 " + manifest(),
                                                 dir_);
    EXPECT_EQ(k8s.exit_code, 0) << k8s.err;
    EXPECT_NE(k8s.out.find("shard 1/3: 2 items: 0 done, 2 up to date"), std::string::npos) << k8s.out;
    const test::Outcome slurm =
        test::run_captured("env -u JOB_COMPLETION_INDEX SLURM_ARRAY_TASK_ID=2 " + std::string(ANIMORDER_EXE) +
                               " batch -q --no-timings" + kEval + " --shard env/3 " + manifest(),
                           dir_);
    EXPECT_NE(slurm.out.find("shard 2/3: 1 items"), std::string::npos) << slurm.out;
}

TEST_F(Batch, CsvManifestIsTheJsonManifest) {
    write(
        "m.json",
        R"({"items": [{"clips": ["walk", "wave"], "options": "-k 2 --views 12 --resolution 32 --max-iterations 2", "output": "out/a"}]})");
    write("m.csv",
          "clips,method,options,output\nwalk;wave,measured,\"-k 2 --views 12 --resolution 32 --max-iterations "
          "2\",out/b\n");
    ASSERT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 0);
    const test::Outcome csv = run("batch -q --eval-views 0 " + path("m.csv").string());
    ASSERT_EQ(csv.exit_code, 0) << csv.err;
    EXPECT_EQ(test::slurp_existing(path("out/a.animorder.bin")), test::slurp_existing(path("out/b.animorder.bin")));
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_TRUE(s["items"][0]["ovr_after"].is_null());  // --eval-views 0
}

TEST_F(Batch, KilledRunResumesWithoutRedoingFinishedItems) {
    // Items slow enough (about a second each) that the kill lands while one is being made.
    std::string items;
    for (int i = 0; i < 4; ++i)
        items += std::string(i ? "," : "") +
                 R"({"options": "-k 3 --views 42 --resolution 48 --max-iterations 2 --seed )" + std::to_string(i + 1) +
                 R"(", "output": "out/item)" + std::to_string(i) + "\"}";
    write("m.json", "{\"items\": [" + items + "]}");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const std::string log = path("first.txt").string();
        if (!std::freopen(log.c_str(), "w", stdout) || dup2(fileno(stdout), 2) < 0) _exit(126);
        execl(ANIMORDER_EXE, ANIMORDER_EXE, "batch", "-q", "--eval-views", "1", "--eval-resolution", "32",
              manifest().c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!fs::exists(path("out/item0.animorder.report.json")) && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the batch ended before the kill: " << test::slurp(path("first.txt"));

    // No item half written: each has all its files (report last) or none of them.
    size_t finished = 0;
    std::map<std::string, std::string> reports;
    for (int i = 0; i < 4; ++i) {
        const std::string stem = path("out/item" + std::to_string(i)).string();
        const bool report = fs::exists(stem + ".animorder.report.json");
        if (report) {
            EXPECT_TRUE(fs::exists(stem + ".animorder.bin") && fs::exists(stem + ".animorder.json")) << stem;
            reports[stem] = test::slurp_existing(stem + ".animorder.report.json");
            ++finished;
        }
    }
    ASSERT_GE(finished, 1u);
    ASSERT_LT(finished, 4u) << "the kill came after the last item: nothing left to resume";

    const test::Outcome again = run("batch -q --eval-views 1 --eval-resolution 32 " + manifest());
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find(std::to_string(4 - finished) + " done, " + std::to_string(finished) + " up to date"),
              std::string::npos)
        << again.out;
    for (const auto& [stem, bytes] : reports)  // wall times included: a redone item would differ
        EXPECT_EQ(test::slurp_existing(stem + ".animorder.report.json"), bytes) << stem;
    for (const auto& [name, bytes] : outputs())
        EXPECT_NE(name[0], '.') << name << ": the killed run's temporary remains";
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["ok"], 4);
}

TEST_F(Batch, ABrokenItemFailsAloneAndTheExitCodeSaysSo) {
    write("broken.gltf",
          "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 7}}]}]}");
    write("m.json", R"({"items": [
      {"name": "good", "method": "static-sander07", "output": "out/good"},
      {"name": "broken", "input": "broken.gltf", "method": "static-sander07", "output": "out/broken"},
      {"name": "absent", "input": "nowhere.glb", "method": "static-sander07", "output": "out/absent"},
      {"name": "good2", "method": "original", "output": "out/good2"}
    ]})");
    const test::Outcome o = run("batch -q" + kEval + " " + manifest());
    EXPECT_EQ(o.exit_code, 3) << o.err;
    EXPECT_EQ(test::line_count(o.err), 2u) << o.err;  // one line per failed item
    EXPECT_NE(o.err.find("broken.gltf"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("nowhere.glb"), std::string::npos) << o.err;
    EXPECT_TRUE(fs::exists(path("out/good.animorder.bin")));
    EXPECT_TRUE(fs::exists(path("out/good2.animorder.bin")));
    EXPECT_FALSE(fs::exists(path("out/broken.animorder.bin")));
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["ok"], 2);
    EXPECT_EQ(s["failed"], 2);
    EXPECT_EQ(s["items"][0]["status"], "ok");
    EXPECT_EQ(s["items"][1]["status"], "failed");
    EXPECT_NE(s["items"][1]["error"].get<std::string>().find("broken.gltf"), std::string::npos);
    EXPECT_TRUE(s["items"][1]["triangles"].is_null());
    EXPECT_EQ(s["items"][3]["status"], "ok");
    const std::string md = test::slurp(path("m.summary.md"));
    EXPECT_NE(md.find("| broken |"), std::string::npos);
    EXPECT_NE(md.find("failed: "), std::string::npos);

    // Once the file is repaired (here: removed from the manifest's list by fixing it to the
    // bundled character), only that item runs.
    write("m.json", R"({"items": [
      {"name": "good", "method": "static-sander07", "output": "out/good"},
      {"name": "broken", "method": "static-sander07", "output": "out/broken"},
      {"name": "good2", "method": "original", "output": "out/good2"}
    ]})");
    const test::Outcome fixed = run("batch -q" + kEval + " " + manifest());
    EXPECT_EQ(fixed.exit_code, 0) << fixed.err;
    EXPECT_NE(fixed.out.find("1 done, 2 up to date, 0 failed"), std::string::npos) << fixed.out;
    EXPECT_FALSE(fs::exists(path("out/broken.animorder.error.json")));
}

TEST_F(Batch, AChangedOptionRerunsOnlyTheItemsItAffects) {
    auto manifest_with = [&](const std::string& k_of_b) {
        write("m.json", R"({"items": [
          {"name": "a", "clips": ["walk"], "options": "-k 2 --views 12 --resolution 32 --max-iterations 2", "output": "out/a"},
          {"name": "b", "clips": ["wave"], "options": "-k )" +
                            k_of_b + R"( --views 12 --resolution 32 --max-iterations 2", "output": "out/b"},
          {"name": "c", "method": "static-sander07", "output": "out/c"}
        ]})");
    };
    manifest_with("2");
    ASSERT_EQ(run("batch -q" + kEval + " " + manifest()).exit_code, 0);
    const std::map<std::string, std::string> first = outputs();

    // Nothing changed, or only the thread count (which changes no output): nothing re-runs.
    const test::Outcome same = run("batch -q --threads 1" + kEval + " " + manifest());
    EXPECT_NE(same.out.find("0 done, 3 up to date"), std::string::npos) << same.out;
    EXPECT_EQ(outputs(), first);

    manifest_with("3");
    const test::Outcome changed = run("batch -q" + kEval + " " + manifest());
    ASSERT_EQ(changed.exit_code, 0) << changed.err;
    EXPECT_NE(changed.out.find("1 done, 2 up to date"), std::string::npos) << changed.out;
    const std::map<std::string, std::string> second = outputs();
    for (const char* name :
         {"a.animorder.bin", "a.animorder.report.json", "c.animorder.bin", "c.animorder.report.json"})
        EXPECT_EQ(second.at(name), first.at(name)) << name;
    EXPECT_NE(second.at("b.animorder.bin"), first.at("b.animorder.bin"));
    EXPECT_EQ(nlohmann::json::parse(second.at("b.animorder.report.json"))["settings"]["clusters"], 3);

    // A batch-wide option the outputs depend on (the evaluation) re-runs every item; --force too.
    const test::Outcome eval = run("batch -q --eval-views 2 --eval-resolution 32 " + manifest());
    EXPECT_NE(eval.out.find("3 done, 0 up to date"), std::string::npos) << eval.out;
    const test::Outcome forced = run("batch -q --force --eval-views 2 --eval-resolution 32 " + manifest());
    EXPECT_NE(forced.out.find("3 done, 0 up to date"), std::string::npos) << forced.out;
}

TEST_F(Batch, EveryOutputIsCheckedBeforeAnyWork) {
    write("m.json", R"({"items": [
      {"method": "original", "output": "out/first"},
      {"method": "original", "output": "missing-folder/second"}
    ]})");
    const test::Outcome o = run("batch -q " + manifest());
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    EXPECT_NE(o.err.find("missing-folder"), std::string::npos) << o.err;
    EXPECT_TRUE(outputs().empty());  // the first item did not run either

    write("prev.animorder.bin", "an input that an output would replace");
    fs::create_directories(path("anims"));
    write("anims/walk.fbx", "a clip");
    for (
        const char* bad :
        {R"({"items": [{"input": "prev.animorder.bin", "output": "out/x"}, {"method": "original", "output": "prev"}]})",
         R"({"items": [{"method": "original", "output": "out/x"}, {"method": "original", "output": "out/x"}]})",
         R"({"items": [{"method": "original", "output": "out/x", "colour": "red"}]})",
         R"({"items": [{"method": "nonsense", "output": "out/x"}]})",
         R"({"items": [{"method": "original", "options": "-o elsewhere", "output": "out/x"}]})",
         R"({"items": [{"method": "original"}]})", "not json",
         // an output, or the summary, in a clip folder (every file of which an item reads)
         R"({"items": [{"input": "prev.animorder.bin", "clips": ["anims/"], "method": "original",
                        "output": "anims/x"}]})",
         R"({"items": [{"method": "original", "output": "anims/x"},
                       {"input": "prev.animorder.bin", "clips": ["anims"], "method": "original",
                        "output": "out/y"}]})"}) {
        write("m.json", bad);  // NOLINT
        const test::Outcome e = run("batch -q " + manifest());
        EXPECT_EQ(e.exit_code, 1) << bad;
        EXPECT_EQ(test::line_count(e.err), 1u) << bad << "\n" << e.err;
        EXPECT_TRUE(outputs().empty()) << bad;
    }
    const test::Outcome shard = run("batch -q --shard 3/3 " + manifest());
    EXPECT_EQ(shard.exit_code, 1);
    EXPECT_EQ(test::line_count(shard.err), 1u) << shard.err;
    write("m.json", R"({"items": [{"method": "original", "output": "out/x"}]})");
    const test::Outcome summary =
        run("batch -q --eval-views 0 --summary " + path("anims/summary").string() + " " + manifest());
    EXPECT_EQ(summary.exit_code, 0) << "no item reads anims/ now: " << summary.err;
    write("m.json", R"({"items": [{"input": "prev.animorder.bin", "clips": ["anims"], "output": "out/y"}]})");
    const test::Outcome in_clips =
        run("batch -q --eval-views 0 --summary " + path("anims/summary2").string() + " " + manifest());
    EXPECT_EQ(in_clips.exit_code, 1);
    EXPECT_NE(in_clips.err.find("clip folder"), std::string::npos) << in_clips.err;
    EXPECT_EQ(test::line_count(in_clips.err), 1u) << in_clips.err;
}

TEST_F(Batch, AChangedInputFileRerunsItsItemAndAGltfItemWritesTheGltf) {
    // A .gltf's external buffer is one of the item's inputs: changing it re-runs that item only.
    const fs::path source = test::shared_data_path("gltf-animated-morph-sphere");
    ANIMORDER_REQUIRE_DATA(source / "AnimatedMorphSphere.gltf");
    fs::create_directories(path("sphere"));
    for (const char* name : {"AnimatedMorphSphere.gltf", "AnimatedMorphSphere.bin"}) {
        fs::copy_file(source / name, path("sphere") / name);
        fs::permissions(path("sphere") / name, fs::perms::owner_write, fs::perm_options::add);
    }
    write("m.json", R"({"items": [
      {"name": "sphere", "input": "sphere/AnimatedMorphSphere.gltf", "method": "static-sander07", "output": "out/sphere.gltf"},
      {"name": "bundled", "method": "original", "output": "out/bundled"}
    ]})");
    const test::Outcome first = run("batch -q" + kEval + " " + manifest());
    ASSERT_EQ(first.exit_code, 0) << first.err;
    EXPECT_TRUE(fs::exists(path("out/sphere.gltf")));
    EXPECT_TRUE(fs::exists(path("out/sphere.animorder.bin")));
    const nlohmann::json report = nlohmann::json::parse(test::slurp(path("out/sphere.animorder.report.json")));
    EXPECT_EQ(report["outputs"]["gltf"], "out/sphere.gltf");  // as the manifest writes it
    EXPECT_EQ(report["outputs"]["sidecar"], "out/sphere.animorder.bin");
    EXPECT_NE(run("batch -q" + kEval + " " + manifest()).out.find("0 done, 2 up to date"), std::string::npos);

    // One bit of the first normal's lowest mantissa byte (bufferView 0: NORMAL floats): same size,
    // still a valid file.
    {
        std::fstream bin(path("sphere/AnimatedMorphSphere.bin"), std::ios::binary | std::ios::in | std::ios::out);
        char byte = 0;
        bin.read(&byte, 1);
        bin.seekp(0);
        bin.put(char(byte ^ 1));
    }
    const test::Outcome changed = run("batch -q" + kEval + " " + manifest());
    EXPECT_NE(changed.out.find("2 items: 1 done, 1 up to date"), std::string::npos) << changed.out << changed.err;
}

namespace {

// `animorder ARGS` run from `folder` (relative manifests), a hang turned into exit 124.
test::Outcome run_from(const fs::path& folder, const std::string& args, const fs::path& scratch) {
    return test::run_captured("cd '" + folder.string() + "' && timeout 120 " + std::string(ANIMORDER_EXE) + " " + args,
                              scratch);
}

// A one-triangle glTF whose buffer (36 bytes: triangle_bytes) is the file `uri` names.
std::string triangle_gltf(const std::string& uri) {
    return nlohmann::json{{"asset", {{"version", "2.0"}}},
                          {"scene", 0},
                          {"scenes", {{{"nodes", {0}}}}},
                          {"nodes", {{{"mesh", 0}}}},
                          {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
                          {"accessors",
                           {{{"bufferView", 0},
                             {"componentType", 5126},
                             {"count", 3},
                             {"type", "VEC3"},
                             {"min", {0, 0, 0}},
                             {"max", {1, 1, 1}}}}},
                          {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                          {"buffers", {{{"byteLength", 36}, {"uri", uri}}}}}
        .dump();
}

std::string triangle_bytes(float z) {
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, z};
    return std::string(reinterpret_cast<const char*>(corners), sizeof corners);
}

}  // namespace

// Files that would never end (a FIFO, /dev/zero as a glTF buffer) fail their item at once, and a
// glTF's external buffer is an input that no output may replace, in batch as in optimize.
TEST_F(Batch, HostileFilesNeitherHangTheRunNorGetReplaced) {
    write("zero.gltf", triangle_gltf("/dev/zero"));  // from a glTF named without a folder: /dev/zero itself
    ASSERT_EQ(::mkfifo(path("pipe.glb").c_str(), 0600), 0);
    ASSERT_EQ(::mkfifo(path("pipe.mtl").c_str(), 0600), 0);
    write("tri.obj", "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");  // the material file a FIFO: skipped
    fs::create_directories(path("loop"));
    fs::create_symlink("self", path("loop/self"));  // a clip folder whose only entry loops
    write("m.json", R"({"items": [
      {"name": "zero", "input": "zero.gltf", "method": "original", "output": "out/zero"},
      {"name": "pipe", "input": "pipe.glb", "method": "original", "output": "out/pipe"},
      {"name": "obj", "input": "tri.obj", "method": "original", "output": "out/obj"},
      {"name": "loop", "input": "tri.obj", "clips": ["loop"], "method": "original", "output": "out/loop"},
      {"name": "writes-it", "method": "original", "output": "out/b"},
      {"name": "reads-an-output", "input": "side.obj", "method": "original", "output": "out/side"}
    ]})");
    // side.obj's material file is the sidecar description the item before it writes (found when
    // loading it, after that item replaced the file: a new inode at the same place).
    write("side.obj", "mtllib out/b.animorder.json\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for (const char* mode : {"", " --merge"}) {
        const test::Outcome o = run_from(dir_, std::string("batch -q --eval-views 0 m.json") + mode, dir_);
        EXPECT_EQ(o.exit_code, 3) << mode << o.err;  // two items failed (merge: their errors are recorded)
    }
    const nlohmann::json summary = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    ASSERT_EQ(summary["items"].size(), 6u);
    EXPECT_EQ(summary["items"][3]["status"], "failed");  // alone: the others ran
    EXPECT_EQ(summary["items"][4]["status"], "ok");
    EXPECT_EQ(summary["items"][5]["status"], "failed");
    EXPECT_NE(summary["items"][5]["error"].get<std::string>().find("b.animorder.json: is an input of this run"),
              std::string::npos)
        << summary["items"][5];
    EXPECT_EQ(summary["items"][0]["status"], "failed");
    EXPECT_NE(summary["items"][0]["error"].get<std::string>().find("reads /dev/zero, which is not a regular file"),
              std::string::npos)
        << summary["items"][0];
    EXPECT_EQ(summary["items"][1]["status"], "failed");
    EXPECT_NE(summary["items"][1]["error"].get<std::string>().find("not a regular file"), std::string::npos);
    EXPECT_EQ(summary["items"][2]["status"], "ok");
    EXPECT_EQ(summary["items"][2]["triangles"], 1);

    // A buffer named like an output: refused before any work, by batch and by optimize.
    write("s.animorder.bin", triangle_bytes(0));
    write("s.gltf", triangle_gltf("s.animorder.bin"));
    write("m.json", R"({"items": [{"input": "s.gltf", "method": "original", "output": "s.glb"}]})");
    const test::Outcome batch = run_from(dir_, "batch -q --eval-views 0 m.json", dir_);
    EXPECT_EQ(batch.exit_code, 1);
    EXPECT_NE(batch.err.find("s.animorder.bin: is an input of this run"), std::string::npos) << batch.err;
    const test::Outcome optimize = run_from(dir_, "optimize -q --method original s.gltf -o s.glb", dir_);
    EXPECT_EQ(optimize.exit_code, 1);
    EXPECT_NE(optimize.err.find("s.animorder.bin: is an input of this run"), std::string::npos) << optimize.err;
    EXPECT_EQ(test::slurp_existing(path("s.animorder.bin")), triangle_bytes(0));
    EXPECT_FALSE(fs::exists(path("s.glb")));
}

// The stamp covers what the loader reads: a percent-encoded buffer URI's file, and an OBJ's
// material file (known only once assimp has opened it: the report lists it with its digest; a
// blended material changes static-sander07's buffer, which sorts blended primitives apart).
TEST_F(Batch, AChangedBufferOrMaterialFileRerunsItsItem) {
    write("my buf.bin", triangle_bytes(0));
    write("tri.gltf", triangle_gltf("my%20buf.bin"));
    write("quad.obj", "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl skin\nf 1 2 3\nf 2 4 3\n");
    write("m.json", R"({"items": [
      {"name": "tri", "input": "tri.gltf", "method": "original", "output": "out/tri"},
      {"name": "quad", "input": "quad.obj", "method": "static-sander07", "output": "out/quad"}
    ]})");
    const std::string batch = "batch -q --eval-views 0 --no-timings " + manifest();
    ASSERT_EQ(run(batch).exit_code, 0);  // quad.mtl is missing: assimp looked for it
    write("quad.mtl", "newmtl skin\nKd 1 0 0\nd 1\n");
    EXPECT_NE(run(batch).out.find("2 items: 1 done, 1 up to date"), std::string::npos);
    const nlohmann::json report = nlohmann::json::parse(test::slurp(path("out/quad.animorder.report.json")));
    ASSERT_GE(report["batch"]["side_files"].size(), 1u) << report["batch"];
    EXPECT_EQ(report["batch"]["side_files"][0]["file"], "../quad.mtl");
    EXPECT_NE(run(batch).out.find("0 done, 2 up to date"), std::string::npos);

    write("my buf.bin", triangle_bytes(0.5f));
    EXPECT_NE(run(batch).out.find("2 items: 1 done, 1 up to date"), std::string::npos);
    const std::string opaque = test::slurp_existing(path("out/quad.animorder.bin"));
    write("quad.mtl", "newmtl skin\nKd 1 0 0\nd 0.5\n");  // now blended: the sidecar flags it
    EXPECT_NE(run(batch).out.find("2 items: 1 done, 1 up to date"), std::string::npos);
    EXPECT_NE(test::slurp_existing(path("out/quad.animorder.bin")), opaque);
}

// A manifest reached by another spelling of its path, a report edited by hand, a folder named
// like a clip in the current folder, and another thread count change nothing.
TEST_F(Batch, SpellingsEditsAndThreadCountsDoNotChangeWhatIsUpToDate) {
    fs::create_directories(path("lib/out"));
    std::ofstream(path("lib/m.json")) << R"({"items": [
      {"name": "walk", "clips": ["walk"], "options": "-k 2 --views 12 --resolution 32 --max-iterations 2", "output": "out/walk"}
    ]})";
    const std::string flags = "-q --no-timings --eval-views 1 --eval-resolution 32 ";
    ASSERT_EQ(run_from(dir_, "batch " + flags + "lib/m.json", dir_).exit_code, 0);
    EXPECT_EQ(run_from(dir_, "batch " + flags + "--merge ./lib/m.json", dir_).exit_code, 0);
    EXPECT_NE(run_from(path("lib"), "batch " + flags + "m.json", dir_).out.find("0 done, 1 up to date"),
              std::string::npos);
    EXPECT_NE(run("batch " + flags + path("lib/m.json").string()).out.find("0 done, 1 up to date"), std::string::npos);

    fs::create_directories(path("walk"));  // a folder named like the clip, where the run starts
    const test::Outcome clip = run_from(dir_, "batch " + flags + "--force lib/m.json", dir_);
    EXPECT_EQ(clip.exit_code, 0) << clip.err;

    std::ofstream(path("lib/out/walk.animorder.report.json")) << R"({"batch": {"stamp": 5}})";
    std::ofstream(path("lib/out/walk.animorder.error.json")) << R"({"stamp": 7, "error": null})";
    const test::Outcome edited = run_from(dir_, "batch " + flags + "lib/m.json", dir_);
    EXPECT_EQ(edited.exit_code, 0) << edited.err;
    EXPECT_NE(edited.out.find("1 done, 0 up to date"), std::string::npos) << edited.out;

    std::map<std::string, std::string> files[2];
    for (int t = 0; t < 2; ++t) {
        ASSERT_EQ(run_from(dir_, "batch " + flags + "--force --threads " + std::to_string(t + 1) + " lib/m.json", dir_)
                      .exit_code,
                  0);
        for (const auto& e : fs::directory_iterator(path("lib/out")))
            files[t][e.path().filename().string()] = test::slurp_existing(e.path());
    }
    EXPECT_EQ(files[0].count("walk.animorder.bin"), 1u) << "no sidecar to compare";
    EXPECT_EQ(files[0], files[1]);
    // The reports name the paths as the manifest writes them: the same bytes from another folder.
    ASSERT_EQ(run_from(path("lib"), "batch " + flags + "--force --threads 1 m.json", dir_).exit_code, 0);
    std::map<std::string, std::string> from_lib;
    for (const auto& e : fs::directory_iterator(path("lib/out")))
        from_lib[e.path().filename().string()] = test::slurp_existing(e.path());
    EXPECT_EQ(from_lib, files[0]);
    EXPECT_NE(from_lib["walk.animorder.report.json"].find(R"("sidecar": "out/walk.animorder.bin")"), std::string::npos)
        << from_lib["walk.animorder.report.json"];
}

// The stamp covers the tool itself, not only its version string: another build (here the same
// executable with one byte more) redoes the items, then finds them up to date.
TEST_F(Batch, AnotherBuildOfTheToolRedoesTheItems) {
    write("m.json",
          R"({"items": [{"name": "walk", "clips": ["walk"],
                  "options": "-k 2 --views 12 --resolution 32 --max-iterations 1", "output": "out/walk"}]})");
    const std::string other = path("animorder-other").string();
    fs::copy_file(ANIMORDER_EXE, other);
    std::ofstream(other, std::ios::binary | std::ios::app) << '\0';
    const std::string args = " batch -q --eval-views 0 " + manifest();
    ASSERT_EQ(run(args.substr(1)).exit_code, 0);
    EXPECT_NE(run(args.substr(1)).out.find("0 done, 1 up to date"), std::string::npos);
    const test::Outcome rebuilt = run_shell(other + args);
    EXPECT_EQ(rebuilt.exit_code, 0) << rebuilt.err;
    EXPECT_NE(rebuilt.out.find("1 done, 0 up to date"), std::string::npos) << rebuilt.out;
    EXPECT_NE(run_shell(other + args).out.find("0 done, 1 up to date"), std::string::npos);
    // A merge by a build other than the one that ran the items finds no current result, and says why.
    EXPECT_EQ(run("batch -q --eval-views 0 --merge " + manifest()).exit_code, 4);
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["items"][0]["status"], "missing");
    EXPECT_NE(s["items"][0]["error"].get<std::string>().find("another animorder build"), std::string::npos)
        << s["items"][0];
    EXPECT_EQ(run_shell(other + " batch -q --eval-views 1 --merge " + manifest()).exit_code, 4);
    EXPECT_NE(nlohmann::json::parse(test::slurp(path("m.summary.json")))["items"][0]["error"].get<std::string>().find(
                  "--eval-views"),
              std::string::npos);
}

// What a killed run left of an item (its temporaries) is removed on the next run even when the
// item is up to date, once the process that wrote it is gone: exited, or a zombie (killed, its
// parent not yet told); a running process's temporaries stay.
TEST_F(Batch, ATemporaryOfAGoneProcessIsRemovedWhenItsItemIsUpToDate) {
    write("m.json",
          R"({"items": [{"name": "walk", "clips": ["walk"],
                  "options": "-k 2 --views 12 --resolution 32 --max-iterations 1", "output": "out/walk"}]})");
    const std::string args = "batch -q --eval-views 0 " + manifest();
    ASSERT_EQ(run(args).exit_code, 0);
    const pid_t exited = ::fork();
    ASSERT_GE(exited, 0);
    if (exited == 0) ::_exit(0);
    ASSERT_EQ(::waitpid(exited, nullptr, 0), exited);
    const pid_t zombie = ::fork();
    ASSERT_GE(zombie, 0);
    if (zombie == 0) ::_exit(0);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // it exits; not waited for: a zombie
    const std::string gone = ".walk.animorder.bin.tmp" + std::to_string(exited);
    const std::string dead = ".walk.animorder.json.tmp" + std::to_string(zombie);
    const std::string alive = ".walk.animorder.report.json.tmp" + std::to_string(::getpid());
    for (const std::string& name : {gone, dead, alive}) write("out/" + name, "half written");
    const test::Outcome again = run(args);
    ::waitpid(zombie, nullptr, 0);
    EXPECT_NE(again.out.find("0 done, 1 up to date"), std::string::npos) << again.out;
    EXPECT_FALSE(fs::exists(path("out/" + gone)));
    EXPECT_FALSE(fs::exists(path("out/" + dead))) << "a zombie writes nothing more";
    EXPECT_TRUE(fs::exists(path("out/" + alive))) << "a running process's temporary was removed";
}

// Manifest mistakes found before any work, each one line: text the JSON reports cannot hold, an
// output naming a folder, files named inside "options", a key or a column given twice, a name too
// long for its temporary; while a CSV's byte order mark and spaces around its fields are fine.
TEST_F(Batch, ManifestMistakesAreRefusedBeforeAnyWork) {
    const std::string long_name(230, 'x');
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"m.csv", "name,method,output\nok,original,out/ok\ncaf\xe9,original,out/cafe\n"},
        {"m.json", R"({"items": [{"method": "original", "output": "out/"}]})"},
        {"m.json", R"({"items": [{"method": "original", "output": "."}]})"},
        {"m.json", R"({"items": [{"method": "original", "options": "chars/Fox.glb", "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "options": "--clip walk", "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "options": "--help", "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "output": "out/a", "output": "out/b"}]})"},
        {"m.csv", "method,output,method\noriginal,out/a,single\n"},
        {"m.json", R"({"items": [{"method": "original", "output": "out/)" + long_name + R"("}]})"},
        // a stray quote, text after a closing quote: never silently dropped
        {"m.csv", "method,output\noriginal,out/a\"b,c\"\n"},
        {"m.csv", "method,output\noriginal,\"out/a\" x\n"},
        // an input given but blank (the bundled character is an item without one)
        {"m.csv", "input,method,output\n  ,original,out/a\n"},
        {"m.json", R"({"items": [{"input": "", "method": "original", "output": "out/a"}]})"},
        // options naming an output, glued to their values
        {"m.json", R"({"items": [{"method": "original", "options": "-revil.json", "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "options": ["-q", "-oevil"], "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "options": "-qrevil.json", "output": "out/a"}]})"},
        // a key the manifest does not know, beside "items"
        {"m.json", R"({"items": [{"method": "original", "output": "out/a"}], "defaults": {"method": "joint"}})"},
        // a NUL, which would cut the path short (another file read, or an output nobody named)
        {"m.json", R"({"items": [{"method": "original", "input": "in.glb\u0000.x", "output": "out/a"}]})"},
        {"m.json", R"({"items": [{"method": "original", "output": "out/a\u0000b"}]})"},
        {"m.csv", std::string("method,output\noriginal,out/a\0b\n", 31)},
        // threads are the batch's: an item's own --threads would be ignored
        {"m.json", R"({"items": [{"method": "original", "options": "--threads 1", "output": "out/a"}]})"},
        // a spreadsheet's "Unicode text" (UTF-16), an empty file
        {"m.csv", std::string("\xFF\xFEm\0e\0t\0h\0o\0d\0", 14)},
        {"m.csv", ""},
        // an object's option keys are names without dashes; a manifest that is neither object nor list
        {"m.json", R"({"items": [{"method": "original", "options": {"": "x"}, "output": "out/a"}]})"},
        {"m.json", "5"}};
    for (const auto& [name, text] : bad) {
        write(name, text);
        const test::Outcome o = run("batch -q --eval-views 0 " + path(name).string());
        EXPECT_EQ(o.exit_code, 1) << text;
        EXPECT_EQ(test::line_count(o.err), 1u) << text << "\n" << o.err;
        EXPECT_TRUE(outputs().empty()) << text;
        fs::remove(path(name));
    }
    // What the errors name: the field at fault, the CSV line, the encoding.
    const std::vector<std::pair<std::string, std::string>> named = {
        {"method,output\noriginal,out/a\noriginal,\n", "m.csv: line 3 has no \"output\""},
        {"method,output\noriginal,out/\xff\n", "line 2: the output is not valid UTF-8"},
        {std::string("\xFF\xFEm\0e\0", 6), "m.csv: is UTF-16 text"},
        {"", "m.csv: line 1: no header line"}};
    for (const auto& [text, expected] : named) {
        write("m.csv", text);
        const test::Outcome o = run("batch -q --eval-views 0 " + path("m.csv").string());
        EXPECT_NE(o.err.find(expected), std::string::npos) << o.err;
    }
    fs::remove(path("m.csv"));
    write("m.json", R"({"items": [{"method": "original", "output": "out/a"}]})");
    for (const char* options : {"--summary out/", "--shard env/0", "--summary /dev/null/x", "--merge --force"}) {
        const test::Outcome o = run("batch -q --eval-views 0 " + std::string(options) + " " + manifest());
        EXPECT_EQ(o.exit_code, 1) << options;
        EXPECT_EQ(test::line_count(o.err), 1u) << options << "\n" << o.err;
    }
    EXPECT_TRUE(outputs().empty());
    // A byte order mark, spaces around fields, CRLF line ends, rows of empty fields (",,", as
    // spreadsheets export them) and an upper-case extension are fine.
    write("M.CSV", "\xEF\xBB\xBFmethod , output\r\n original , \"out/a\" \r\n,\r\n , \r\n");
    const test::Outcome bom = run("batch -q --eval-views 0 " + path("M.CSV").string());
    EXPECT_EQ(bom.exit_code, 0) << bom.err;
    EXPECT_TRUE(fs::exists(path("out/a.animorder.bin")));
    EXPECT_EQ(nlohmann::json::parse(test::slurp(path("M.summary.json")))["items"].size(), 1u);
}

// A report whose figures were edited into something else is not a result: the merge lists the
// item as missing (not "ok" with the edited figures) and the next run redoes it.
TEST_F(Batch, AReportEditedByHandIsStaleNotTrusted) {
    write("m.json",
          R"({"items": [{"method": "original", "output": "out/a"}, {"method": "original", "output": "out/b"}]})");
    ASSERT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 0);
    nlohmann::json report = nlohmann::json::parse(test::slurp(path("out/a.animorder.report.json")));
    report["batch"]["triangles"] = "lots";
    write("out/a.animorder.report.json", report.dump());
    const test::Outcome merged = run("batch -q --eval-views 0 --merge " + manifest());
    EXPECT_EQ(merged.exit_code, 4) << merged.err;
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["items"][0]["status"], "missing");
    EXPECT_TRUE(s["items"][0]["triangles"].is_null());
    EXPECT_EQ(s["items"][1]["status"], "ok");
    const test::Outcome again = run("batch -q --eval-views 0 " + manifest());
    EXPECT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("1 done, 1 up to date"), std::string::npos) << again.out;
    // A "batch" that is no object at all (the merge stopped on it with a JSON type error).
    for (const char* edited : {R"({"batch": null})", R"({"batch": [1]})", R"({"batch": "x"})"}) {
        write("out/a.animorder.report.json", edited);
        const test::Outcome m = run("batch -q --eval-views 0 --merge " + manifest());
        EXPECT_EQ(m.exit_code, 4) << edited << ": " << m.err;
        EXPECT_EQ(nlohmann::json::parse(test::slurp(path("m.summary.json")))["items"][0]["status"], "missing");
    }
}

// A shard checks for writing only the files it writes, and the merge only the summary: another
// shard's output folder that is missing here (a farm's pods may mount only their own) stops
// neither; the shard that writes there refuses at once. A failed item's row in a merge with other
// --eval-* options than its run says that its last run failed, and why.
TEST_F(Batch, AShardChecksOnlyWhatItWritesAndTheMergeOnlyTheSummary) {
    write("m.json", R"({"items": [
      {"method": "original", "output": "out/a"},
      {"method": "original", "output": "elsewhere/b"},
      {"input": "broken.obj", "method": "original", "output": "out/c"}
    ]})");
    write("broken.obj", "v 0 0 0\nf 1 2 3\n");
    const test::Outcome mine = run("batch -q --eval-views 0 --shard 0/3 " + manifest());
    EXPECT_EQ(mine.exit_code, 0) << mine.err;
    EXPECT_TRUE(fs::exists(path("out/a.animorder.bin")));
    const test::Outcome theirs = run("batch -q --eval-views 0 --shard 1/3 " + manifest());
    EXPECT_EQ(theirs.exit_code, 1);
    EXPECT_NE(theirs.err.find("elsewhere does not exist"), std::string::npos) << theirs.err;
    EXPECT_EQ(run("batch -q --eval-views 0 --shard 2/3 " + manifest()).exit_code, 3);
    fs::create_directories(path("summaries"));
    const test::Outcome merged =
        run("batch -q --eval-views 1 --merge --summary " + path("summaries/s").string() + " " + manifest());
    EXPECT_EQ(merged.exit_code, 4) << merged.err;
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("summaries/s.json")));
    EXPECT_NE(s["items"][1]["error"].get<std::string>().find("no result yet"), std::string::npos) << s["items"][1];
    EXPECT_NE(s["items"][2]["error"].get<std::string>().find(
                  "evaluated with other --eval-views/--eval-resolution/--no-timings; it failed when it last ran: "),
              std::string::npos)
        << s["items"][2];
    EXPECT_NE(s["items"][2]["error"].get<std::string>().find("broken.obj"), std::string::npos) << s["items"][2];
}

// The Kubernetes Indexed Job of docs/batch.md (once in the README) runs its container command once
// per index: a pod whose shard has a broken item completes (the failure is recorded, not retried),
// and the merge step then lists it with exit code 3. The command is taken from docs/batch.md as written.
TEST_F(Batch, TheReadmesKubernetesCommandCompletesAShardWithAFailedItem) {
    const std::string readme = test::slurp(fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "batch.md");
    const std::string marker = "command: [";
    const size_t at = readme.find(marker);
    ASSERT_NE(at, std::string::npos) << "docs/batch.md's Job has no command";
    const size_t open = at + marker.size() - 1;
    const nlohmann::json words = nlohmann::json::parse(readme.substr(open, readme.find(']', open) - open + 1));
    ASSERT_GE(words.size(), 3u);
    ASSERT_EQ(words[0], "animorder");  // the container's PID 1: no shell that would not pass SIGTERM on
    ASSERT_EQ(words[2], "/library/manifest.json");
    std::string command = std::string(ANIMORDER_EXE) + " " + words[1].get<std::string>() + " " + manifest();
    for (size_t w = 3; w < words.size(); ++w) command += " " + words[w].get<std::string>();
    ASSERT_EQ(command.find('\''), std::string::npos) << command;
    write("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": 7}");
    write("m.json", R"({"items": [{"method": "original", "output": "out/good"},
                                  {"input": "broken.gltf", "method": "original", "output": "out/broken"}]})");
    for (const char* index : {"0", "1"}) {
        const std::string pod_command = "JOB_COMPLETION_INDEX=" + std::string(index) + " sh -c '" + command + "'";
        const test::Outcome pod = run_shell(pod_command);
        EXPECT_EQ(pod.exit_code, 0) << "index " << index << ": " << pod.err;
    }
    EXPECT_TRUE(fs::exists(path("out/good.animorder.bin")));
    EXPECT_TRUE(fs::exists(path("out/broken.animorder.error.json")));
    const test::Outcome merged = run("batch -q --merge " + manifest());
    EXPECT_EQ(merged.exit_code, 3) << merged.err;
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["ok"], 1);
    EXPECT_EQ(s["failed"], 1);
    // An error before any work (here a manifest that is not JSON) still fails the pod.
    write("m.json", "not json");
    EXPECT_EQ(run_shell("JOB_COMPLETION_INDEX=0 sh -c '" + command + "'").exit_code, 1);
}

// docs/batch.md's SLURM lines, as written, on a real one-node SLURM (Debian's slurm-wlm and munge,
// started in the test's folder by tests/tool/one-node-slurm.sh): the array job's tasks run the
// manifest's items as shards on the cluster, the merge writes the summary, and every file and the
// summary are the bytes of one local run of the same manifest.
TEST_F(Batch, TheManualsSlurmArrayJobGivesTheFilesAndSummaryOfOneLocalRun) {
    const std::string doc = test::slurp(fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "batch.md");
    const size_t open = doc.find("```sh\nsbatch ");
    ASSERT_NE(open, std::string::npos) << "docs/batch.md has no SLURM block";
    const size_t begin = open + 6, end = doc.find("```", begin);
    const std::string lines = doc.substr(begin, end - begin);
    ASSERT_NE(lines.find("--array="), std::string::npos) << lines;
    ASSERT_NE(lines.find("--wait"), std::string::npos) << lines;  // else the merge would not wait for the tasks

    // The cluster's folder: a second scratch folder of this test, with a short path (slurmd's
    // sockets live in it, and a Unix socket's path has at most 108 bytes).
    char cluster_template[] = "/tmp/animorder-slurm-XXXXXX";
    ASSERT_NE(::mkdtemp(cluster_template), nullptr);
    const std::string cluster = cluster_template;
    const std::string script = std::string(ANIMORDER_SOURCE_DIR) + "/tests/tool/one-node-slurm.sh";
    const test::Outcome started = run_shell("bash " + script + " start " + cluster);
    struct Stop {  // the daemons end with the test, whatever it did, and their folder goes
        std::string command, folder;
        ~Stop() {
            if (std::system(command.c_str()) != 0) ADD_FAILURE() << command;
            fs::remove_all(folder);
        }
    } stop{"bash " + script + " stop " + cluster + " > /dev/null 2>&1", cluster};
    ANIMORDER_REQUIRE_OR_SKIP("slurm", started.exit_code == 0,
                              "no one-node SLURM could be started: " + started.err);
    const std::string conf = started.out.substr(0, started.out.find('\n'));
    ASSERT_EQ(conf.rfind("SLURM_CONF=", 0), 0u) << started.out;

    // Several characters: the bundled one (clips, joint, static methods) and the same exported
    // as a glTF binary with a clip of its own.
    ASSERT_EQ(run("subdivide -q --levels 0 --clip wave -o " + path("wave.glb").string()).exit_code, 0);
    std::string items = kFiveItems;
    items.replace(items.rfind("]}"), 2,
                  ",\n  {\"name\": \"wave-glb\", \"input\": \"wave.glb\", \"options\": \"" + kFast +
                      "\", \"output\": \"out/wave-glb\"},\n"
                      "  {\"name\": \"wave-glb-sander\", \"input\": \"wave.glb\", \"method\": \"static-sander07\", "
                      "\"output\": \"out/wave-glb-sander\"}\n]}");
    write("manifest.json", items);
    const test::Outcome local = run("batch -q --no-timings " + path("manifest.json").string());
    ASSERT_EQ(local.exit_code, 0) << local.err;
    const std::map<std::string, std::string> local_files = outputs();
    const std::string summary_json = test::slurp_existing(path("manifest.summary.json")),
                      summary_md = test::slurp_existing(path("manifest.summary.md"));
    ASSERT_EQ(local_files.size(), 7u * 3u);  // each item: sidecar, its description, its report
    for (const auto& e : fs::directory_iterator(path("out"))) fs::remove(e.path());
    fs::remove(path("manifest.summary.json"));
    fs::remove(path("manifest.summary.md"));

    // The lines as written, with this build's animorder first on the PATH (sbatch passes the
    // environment on to the tasks) and a bound on the whole: a cluster that never ran the tasks
    // fails the test, not CI's time limit.
    write("slurm-lines.sh", "set -e\n" + lines);
    const std::string bin = fs::path(ANIMORDER_EXE).parent_path().string();
    const test::Outcome farm =
        run_shell("cd " + dir_.string() + " && env " + conf + " PATH=" + bin + ":\"$PATH\" timeout 600 bash slurm-lines.sh");
    ASSERT_EQ(farm.exit_code, 0) << farm.out << farm.err;
    // Every task ran on the cluster (its output file: slurm-JOB_TASK.out), shards beyond the
    // items' count with nothing to do.
    size_t task_logs = 0;
    for (const auto& e : fs::directory_iterator(dir_))
        task_logs += e.path().filename().string().rfind("slurm-", 0) == 0 && e.path().extension() == ".out";
    EXPECT_EQ(task_logs, 50u);
    EXPECT_EQ(outputs(), local_files);
    EXPECT_EQ(test::slurp_existing(path("manifest.summary.json")), summary_json);
    EXPECT_EQ(test::slurp_existing(path("manifest.summary.md")), summary_md);
}

// An output emptied or changed after its run is not up to date: the item is redone (only the
// presence of the files was checked before), and the redone file is the first run's again.
TEST_F(Batch, ADamagedOutputIsRedoneNotTakenAsUpToDate) {
    write("m.json",
          R"({"items": [{"name": "walk", "clips": ["walk"], "options": ")" + kFast + R"(", "output": "out/walk"},
                        {"name": "orig", "method": "original", "output": "out/orig"}]})");
    const std::string args = "batch -q --eval-views 0 --no-timings " + manifest();
    ASSERT_EQ(run(args).exit_code, 0);
    const std::string bin = test::slurp_existing(path("out/walk.animorder.bin")),
                      json = test::slurp_existing(path("out/orig.animorder.json"));
    write("out/walk.animorder.bin", "");
    std::string changed = json;
    changed[changed.size() / 2] ^= 1;  // the same size, one bit off
    write("out/orig.animorder.json", changed);
    const test::Outcome again = run(args);
    EXPECT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("2 done, 0 up to date"), std::string::npos) << again.out;
    EXPECT_EQ(test::slurp_existing(path("out/walk.animorder.bin")), bin);
    EXPECT_EQ(test::slurp_existing(path("out/orig.animorder.json")), json);
    EXPECT_NE(run(args).out.find("0 done, 2 up to date"), std::string::npos);
}

// An item that fails in this run is "failed" in this run's summary, even when an earlier result of
// it still matches the stamp the run began with (--force redid it; an input was edited while it
// ran). Its earlier files are left as they were; once the input is as before, the item is up to
// date again and its error file goes.
TEST_F(Batch, AnItemThatFailsNowIsFailedInTheSummaryAndItsErrorGoesOnceUpToDate) {
    ASSERT_EQ(run("subdivide -q --levels 0 --clip walk -o " + path("in.glb").string()).exit_code, 0);
    const std::string input = test::slurp_existing(path("in.glb"));
    write("m.json", R"({"items": [{"name": "slow", "input": "in.glb",
                  "options": "-k 3 --views 42 --resolution 64 --max-iterations 3", "output": "out/slow"}]})");
    ASSERT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 0);
    const std::string bin = test::slurp_existing(path("out/slow.animorder.bin"));

    // --force, and the input edited once the item runs (after its stamp: the "running" line).
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const std::string log = path("forced.txt").string();
        if (!std::freopen(log.c_str(), "w", stdout) || dup2(fileno(stdout), 2) < 0) _exit(126);
        execl(ANIMORDER_EXE, ANIMORDER_EXE, "batch", "--force", "--eval-views", "0", manifest().c_str(),
              static_cast<char*>(nullptr));
        _exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (test::slurp(path("forced.txt")).find("slow: running") == std::string::npos &&
           std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    kill(child, SIGSTOP);
    std::ofstream(path("in.glb"), std::ios::binary | std::ios::app) << '\0';
    kill(child, SIGCONT);
    int status = 0;
    waitpid(child, &status, 0);
    const std::string log = test::slurp(path("forced.txt"));
    ASSERT_TRUE(WIFEXITED(status)) << log;
    EXPECT_EQ(WEXITSTATUS(status), 3) << log;
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["ok"], 0) << s;
    EXPECT_EQ(s["failed"], 1) << s;
    EXPECT_EQ(s["items"][0]["status"], "failed");
    EXPECT_FALSE(s["items"][0]["error"].get<std::string>().empty());
    EXPECT_EQ(test::slurp_existing(path("out/slow.animorder.bin")), bin) << "the earlier result was replaced";
    EXPECT_TRUE(fs::exists(path("out/slow.animorder.error.json")));

    write("in.glb", input);
    const test::Outcome again = run("batch -q --eval-views 0 " + manifest());
    EXPECT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("0 done, 1 up to date"), std::string::npos) << again.out;
    EXPECT_FALSE(fs::exists(path("out/slow.animorder.error.json"))) << "a stale failure marker stayed";
}

// The merge's exit code when items failed and others have no result yet: 5, so that a farm's
// pipeline learns of both (the counts are in the summary).
TEST_F(Batch, AMergeWithFailedAndMissingItemsExitsFive) {
    write("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": 7}");
    write("m.json", R"({"items": [{"input": "broken.gltf", "method": "original", "output": "out/broken"},
                                  {"method": "original", "output": "out/never"}]})");
    EXPECT_EQ(run("batch -q --eval-views 0 --shard 0/2 " + manifest()).exit_code, 3);
    EXPECT_EQ(run("batch -q --eval-views 0 --merge " + manifest()).exit_code, 5);
    const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
    EXPECT_EQ(s["failed"], 1);
    EXPECT_EQ(s["missing"], 1);
    EXPECT_NE(s["items"][1]["error"].get<std::string>().find("no result yet"), std::string::npos) << s["items"][1];
}

// The summary is the same bytes whichever folder the batch starts in, failed rows included (their
// errors named the input as resolved from the current folder); --summary S.json names S.json and S.md.
TEST_F(Batch, AFailedRowIsTheSameFromAnyFolderAndSummaryTakesItsJsonName) {
    fs::create_directories(path("lib/out"));
    write("lib/m.json", R"({"items": [{"input": "missing.glb", "method": "original", "output": "out/a"},
                                      {"method": "original", "output": "out/b"}]})");
    const std::string options = " -q --no-timings --eval-views 0 --threads 1 ";
    EXPECT_EQ(run_from(path("lib"), "batch" + options + "m.json", dir_).exit_code, 3);
    const std::string from_lib = test::slurp_existing(path("lib/m.summary.json"));
    EXPECT_NE(from_lib.find("missing.glb"), std::string::npos) << from_lib;
    EXPECT_EQ(run_from(dir_, "batch" + options + "lib/m.json", dir_).exit_code, 3);
    EXPECT_EQ(test::slurp_existing(path("lib/m.summary.json")), from_lib);
    EXPECT_EQ(run_from(dir_, "batch" + options + "--merge --summary lib/s.json lib/m.json", dir_).exit_code, 3);
    EXPECT_EQ(test::slurp_existing(path("lib/s.json")), from_lib);
    EXPECT_TRUE(fs::exists(path("lib/s.md")));
    EXPECT_FALSE(fs::exists(path("lib/s.json.json")));
}

// --dry-run writes nothing and says, per item of the shard, whether a run would redo it and which
// part of its stamp or which output is why: each change below is made by hand, so the reasons
// are known independently of batch.
TEST_F(Batch, ADryRunSaysWhatWouldRunAndWhyAndWritesNothing) {
    write("tri.bin", triangle_bytes(0));
    write("tri.gltf", triangle_gltf("tri.bin"));
    const auto manifest_with = [&](const std::string& k_of_b) {
        write("m.json", R"({"items": [
          {"name": "a", "clips": ["walk"], "options": "-k 2 --views 12 --resolution 32 --max-iterations 2", "output": "out/a"},
          {"name": "b", "clips": ["wave"], "options": "-k )" +
                            k_of_b + R"( --views 12 --resolution 32 --max-iterations 2", "output": "out/b"},
          {"name": "tri", "input": "tri.gltf", "method": "original", "output": "out/tri"},
          {"name": "c", "method": "original", "output": "out/c"}
        ]})");
    };
    manifest_with("2");
    const auto plan = [&](const std::string& options) {  // --eval-views 0 unless given
        const std::string eval = options.find("--eval-views") == std::string::npos ? " --eval-views 0" : "";
        const test::Outcome o =
            run("batch -q --dry-run --summary " + path("sums/s").string() + eval + options + " " + manifest());
        EXPECT_EQ(o.exit_code, 0) << o.err;
        return nlohmann::json::parse(o.out);
    };
    const auto whys = [](const nlohmann::json& p) {
        std::vector<std::string> out;
        for (const auto& item : p["items"])
            out.push_back(item["action"].get<std::string>() + ": " + item["why"].get<std::string>());
        return out;
    };
    const std::string none = "run: no result yet (not run, or its run did not finish)";
    fs::create_directories(path("sums"));
    const auto folder_time = fs::last_write_time(path("out")), summary_folder_time = fs::last_write_time(path("sums"));
    nlohmann::json p = plan("");
    EXPECT_EQ(whys(p), std::vector<std::string>(4, none));
    // Not even a file created and removed (the checks of a run probe each folder that way).
    EXPECT_EQ(fs::last_write_time(path("out")), folder_time);
    EXPECT_EQ(fs::last_write_time(path("sums")), summary_folder_time);
    EXPECT_EQ(p["run"], 4);
    EXPECT_TRUE(outputs().empty());
    EXPECT_FALSE(fs::exists(path("m.summary.json")));

    ASSERT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 0);
    const std::map<std::string, std::string> written = outputs();
    EXPECT_EQ(whys(plan("")), std::vector<std::string>(4, "skip: up to date"));
    EXPECT_EQ(whys(plan(" --force")), std::vector<std::string>(4, "run: --force"));
    const nlohmann::json evaluated = plan(" --eval-views 1");
    EXPECT_NE(evaluated["items"][0]["why"].get<std::string>().find("--eval-views"), std::string::npos);

    manifest_with("3");
    write("tri.bin", triangle_bytes(0.5f));
    fs::remove(path("out/c.animorder.bin"));
    p = plan("");
    EXPECT_EQ(whys(p), (std::vector<std::string>{"skip: up to date", "run: its options changed since it ran",
                                                 "run: its input tri.bin changed since it ran",
                                                 "run: its output out/c.animorder.bin is missing"}));
    EXPECT_EQ(p["run"], 3);
    EXPECT_EQ(p["skip"], 1);
    // A shard's plan lists its own items only.
    p = plan(" --shard 1/2");
    ASSERT_EQ(p["items"].size(), 2u);
    EXPECT_EQ(p["items"][0]["name"], "b");
    EXPECT_EQ(p["items"][1]["name"], "c");
    EXPECT_EQ(p["shard"], nlohmann::json::array({1, 2}));
    // Nothing was written or removed by any of the plans.
    std::map<std::string, std::string> now = outputs();
    EXPECT_EQ(now.size() + 1, written.size());
    for (const auto& [name, bytes] : now) EXPECT_EQ(bytes, written.at(name)) << name;
    // A failed item says so, with its error.
    write("tri.gltf", "{");
    EXPECT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 3);
    EXPECT_NE(plan("")["items"][2]["why"].get<std::string>().find("it failed when it last ran: "), std::string::npos);
    // ... and, once something changed since, what changed and that it failed (it said "no result yet").
    const std::string changed = plan(" --eval-views 1")["items"][2]["why"].get<std::string>();
    EXPECT_NE(changed.find("--eval-views"), std::string::npos) << changed;
    EXPECT_NE(changed.find("; it failed when it last ran: "), std::string::npos) << changed;
    EXPECT_NE(run("batch -q --dry-run --merge " + manifest()).err.find("drop --dry-run"), std::string::npos);
}

// As a container's first process (PID 1, where a signal's default action does nothing), batch
// still ends on SIGTERM, as Kubernetes sends it when a pod is deleted: exit 143 (128 + 15), its
// item unwritten. It ran on to the end before, until the grace period's SIGKILL.
TEST_F(Batch, AsAContainersFirstProcessItEndsOnSigterm) {
    ANIMORDER_REQUIRE_OR_SKIP("namespaces", run_shell("unshare -p -f --mount-proc true").exit_code == 0,
                              "a PID namespace cannot be made here: `unshare -p -f --mount-proc true` failed "
                              "(unshare is in util-linux; -p needs root)");
    write("m.json", R"({"items": [{"options": "--views 642 --resolution 512", "output": "out/a"}]})");
    const std::string script = "unshare -p -f --mount-proc " + std::string(ANIMORDER_EXE) + " batch --eval-views 0 " +
                               manifest() + " 2> err.txt & u=$!; " +
                               "for i in $(seq 300); do grep -q running err.txt && break; sleep 0.1; done; " +
                               "kill -TERM $(pgrep -P $u); wait $u; echo rc=$?";
    const test::Outcome o = run_shell("cd '" + dir_.string() + "' || exit 1; " + script);
    EXPECT_NE(o.out.find("rc=143"), std::string::npos) << o.out << test::slurp(path("err.txt"));
    EXPECT_FALSE(fs::exists(path("out/a.animorder.bin")));
}

// The files an importer looked for are listed in the report as found from the report's folder,
// the same whatever folder the batch starts in: assimp's MD5 reader also looks for names made
// from the input's path as spelled ("chars/chars/Bob.md5anim", cut-off names), which were
// listed and differed with the spelling.
TEST_F(Batch, AReportIsTheSameBytesFromAnyFolderWhenTheImporterProbes) {
    const fs::path bob = test::shared_data_path("md5-bob");
    ANIMORDER_REQUIRE_DATA(bob / "Bob.md5mesh");
    fs::create_directories(path("chars/anims"));
    fs::copy_file(bob / "Bob.md5mesh", path("chars/Bob.md5mesh"));
    fs::copy_file(bob / "Bob.md5anim", path("chars/anims/Bob.md5anim"));
    write("m.json", R"({"items": [{"input": "chars/Bob.md5mesh", "clips": ["chars/anims/"], "method": "original",
                                   "output": "out/bob"}]})");
    const std::string report = path("out/bob.animorder.report.json").string();
    ASSERT_EQ(run_from(dir_, "batch -q --eval-views 0 --no-timings m.json", dir_).exit_code, 0);
    const std::string first = test::slurp_existing(report);
    const nlohmann::json side = nlohmann::json::parse(first)["batch"]["side_files"];
    ASSERT_EQ(side.size(), 1u) << side;  // the anim beside the mesh, looked for and missing
    EXPECT_EQ(side[0]["file"], "../chars/Bob.md5anim");
    for (const std::string& spelling : {manifest(), std::string("./m.json")}) {
        const test::Outcome o = run_from(spelling == manifest() ? fs::path("/") : dir_,
                                         "batch -q --eval-views 0 --no-timings --force '" + spelling + "'", dir_);
        ASSERT_EQ(o.exit_code, 0) << o.err;
        EXPECT_EQ(test::slurp_existing(report), first) << spelling;
    }
}

// A CSV error names the line it is on, a quoted field over several lines counted (the record
// count was named), also for an item's options; the Markdown summary escapes a name's
// punctuation instead of changing it ("a|b" was shown as "a/b", a name's *stars* as emphasis).
TEST_F(Batch, CsvErrorsNameTheirLineAndTheMarkdownSummaryEscapesNames) {
    write("m.csv", "name,method,output\n\"multi\nline\",original,out/a\nb,original,out/\"b\n");
    test::Outcome o = run("batch -q --eval-views 0 " + path("m.csv").string());
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_NE(o.err.find("m.csv: line 4: field 3: a quote inside an unquoted field"), std::string::npos) << o.err;
    write("m.csv", "name,method,options,output\n\"multi\nline\",original,,out/a\nb,original,--no-such-option,out/b\n");
    o = run("batch -q --eval-views 0 " + path("m.csv").string());
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_NE(o.err.find("line 4 (b): "), std::string::npos) << o.err;

    write("m.json", R"({"items": [{"name": "a|b", "method": "original", "output": "out/a"},
                                  {"name": "a/b", "method": "original", "output": "out/b"},
                                  {"name": "*em* <i>x</i> `c`", "method": "original", "output": "out/c"}]})");
    ASSERT_EQ(run("batch -q --eval-views 0 " + manifest()).exit_code, 0);
    const std::string md = test::slurp(path("m.summary.md"));
    EXPECT_NE(md.find("\n| a\\|b | original |"), std::string::npos) << md;
    EXPECT_NE(md.find("\n| a/b | original |"), std::string::npos) << md;
    EXPECT_NE(md.find("\n| \\*em\\* \\<i\\>x\\</i\\> \\`c\\` | original |"), std::string::npos) << md;
}

// A shard that is empty or malformed is refused before any work, in one line: in a farm whose
// index variable is unset, `--shard "$JOB_COMPLETION_INDEX/4"` reads "/4" and `--shard "$SHARD"`
// reads "" (which ran every item, in every process of the job).
TEST_F(Batch, AnEmptyOrMalformedShardIsRefusedBeforeAnyWork) {
    write("m.json",
          R"({"items": [{"method": "original", "output": "out/a"}, {"method": "original", "output": "out/b"}]})");
    for (const char* shard : {"", "/4", "3/", "/", "4/4", "-1/4", "x/4", "1/x", " ", "\t", " 1/4", "1/4 ", "1 /4",
                              "1/0", "+1/4", "1/4/2", "env/", "1//4"}) {
        for (const char* mode : {"", " --dry-run"}) {
            const test::Outcome o =
                run("batch -q --eval-views 0" + std::string(mode) + " --shard '" + shard + "' " + manifest());
            EXPECT_EQ(o.exit_code, 1) << "'" << shard << "'" << mode << ": " << o.out;
            EXPECT_EQ(test::line_count(o.err), 1u) << "'" << shard << "'" << mode << ": " << o.err;
            EXPECT_NE(o.err.find("--shard"), std::string::npos) << o.err;
            EXPECT_EQ(o.out, "") << "'" << shard << "'" << mode;
            EXPECT_TRUE(outputs().empty()) << "'" << shard << "'" << mode;
        }
    }
    // As a farm's command writes it, with the variable unset.
    const std::string exe = ANIMORDER_EXE;
    for (const char* shard : {"\"$JOB_COMPLETION_INDEX/4\"", "\"$SHARD\"", "\"$SHARD\"/2"}) {
        const test::Outcome o = run_shell("env -u JOB_COMPLETION_INDEX -u SHARD sh -c '" + exe +
                                          " batch -q --eval-views 0 --shard " + shard + " " + manifest() + "'");
        EXPECT_EQ(o.exit_code, 1) << shard;
        EXPECT_NE(o.err.find("is empty (an unset variable"), std::string::npos) << shard << ": " << o.err;
        EXPECT_TRUE(outputs().empty()) << shard;
    }
    // A well-formed shard still runs its own items.
    const test::Outcome one = run("batch -q --eval-views 0 --shard 01/2 " + manifest());
    EXPECT_EQ(one.exit_code, 0) << one.err;
    EXPECT_NE(one.out.find("shard 1/2: 1 items: 1 done"), std::string::npos) << one.out;
    EXPECT_TRUE(fs::exists(path("out/b.animorder.bin")));
    EXPECT_FALSE(fs::exists(path("out/a.animorder.bin")));
}

// An item's files outside the manifest's folder (an output with "..", an absolute one, one
// through a link to a folder elsewhere) are refused before any work, in one line naming the item
// and the path, unless --allow-outside; with it they are written, and resume as any other. The
// manifest lives in lib/, the outside folder is elsewhere/: both in the test's folder.
TEST_F(Batch, OutputsOutsideTheManifestsFolderNeedAllowOutside) {
    fs::create_directories(path("lib/out"));
    fs::create_directories(path("elsewhere"));
    fs::create_symlink("../elsewhere", path("lib/link"));
    const std::string lib_manifest = path("lib/m.json").string();
    const std::vector<std::string> outside = {"../elsewhere/a", path("elsewhere/b").string(), "out/../../elsewhere/c",
                                              "link/d"};
    const auto files_in = [&](const char* folder) {
        size_t n = 0;
        for (const auto& e : fs::directory_iterator(path(folder))) n += e.is_regular_file();
        return n;
    };
    for (const std::string& output : outside) {
        write("lib/m.json", R"({"items": [{"name": "in", "method": "original", "output": "out/in"},
                                          {"name": "out", "method": "original", "output": ")" +
                                output + "\"}]}");
        for (const char* mode : {"", " --dry-run", " --shard 1/2", " --merge"}) {
            const test::Outcome o = run("batch -q --eval-views 0" + std::string(mode) + " " + lib_manifest);
            EXPECT_EQ(o.exit_code, 1) << output << mode;
            EXPECT_EQ(test::line_count(o.err), 1u) << output << mode << ": " << o.err;
            EXPECT_NE(o.err.find("item 2 (out): the output " + output), std::string::npos) << o.err;
            EXPECT_NE(o.err.find("--allow-outside"), std::string::npos) << o.err;
        }
        EXPECT_EQ(files_in("elsewhere"), 0u) << output;
        EXPECT_EQ(files_in("lib/out"), 0u) << output;  // before any work: not even the item inside
    }
    // Allowed: written where they lead, and up to date on the next run and in the merge.
    std::string items;
    for (size_t i = 0; i < outside.size(); ++i)
        items += std::string(i ? "," : "") + R"({"method": "original", "output": ")" + outside[i] + "\"}";
    write("lib/m.json", "{\"items\": [" + items + "]}");
    const test::Outcome allowed = run("batch -q --eval-views 0 --allow-outside " + lib_manifest);
    EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
    for (const char* name : {"a", "b", "c", "d"})
        for (const char* ext : {".animorder.bin", ".animorder.json", ".animorder.report.json"})
            EXPECT_TRUE(fs::exists(path("elsewhere/" + std::string(name) + ext))) << name << ext;
    const test::Outcome again = run("batch -q --eval-views 0 --allow-outside " + lib_manifest);
    EXPECT_NE(again.out.find("4 items: 0 done, 4 up to date"), std::string::npos) << again.out << again.err;
    EXPECT_EQ(run("batch -q --eval-views 0 --allow-outside --merge " + lib_manifest).exit_code, 0);
    EXPECT_EQ(nlohmann::json::parse(test::slurp(path("lib/m.summary.json")))["ok"], 4);
    // Paths that only pass through folders and come back inside are inside.
    fs::create_directories(path("lib/sub"));
    write("lib/m.json", R"({"items": [{"method": "original", "output": "sub/../out/x"},
                                      {"method": "original", "output": ")" +
                            path("lib/out/y").string() + "\"}]}");
    const test::Outcome inside = run("batch -q --eval-views 0 " + lib_manifest);
    EXPECT_EQ(inside.exit_code, 0) << inside.err;
    EXPECT_TRUE(fs::exists(path("lib/out/x.animorder.bin")));
    EXPECT_TRUE(fs::exists(path("lib/out/y.animorder.bin")));
}

// The merge's line about a refused report stays one line on a terminal whatever the item's name
// holds: its control bytes (ESC, which could drive the terminal) written as \xNN.
TEST_F(Batch, TheMergesLineAboutARefusedReportEscapesTheItemsName) {
    write("m.json", R"({"items": [{"name": "e\u001b[2Jvil", "method": "original", "output": "out/a"}]})");
    const std::string options = "batch -q --eval-views 1 --eval-resolution 32 ";
    ASSERT_EQ(run(options + manifest()).exit_code, 0);
    nlohmann::json report = nlohmann::json::parse(test::slurp_existing(path("out/a.animorder.report.json")));
    report["batch"]["ovr_after"] = 1e308;
    write("out/a.animorder.report.json", report.dump(2));
    const test::Outcome merged = run(options + "--merge " + manifest());
    EXPECT_EQ(merged.exit_code, 4) << merged.err;
    EXPECT_EQ(merged.err.find('\x1b'), std::string::npos) << merged.err;
    EXPECT_NE(merged.err.find("e\\x1b[2Jvil: "), std::string::npos) << merged.err;
    EXPECT_EQ(test::line_count(merged.err), 1u) << merged.err;
}

// A report that carries its item's stamp but a figure no run gives (an OVR of 1e308 or below 1, an
// ACMR outside 1/triangles..3, a negative count or time, a number JSON cannot hold) is not a
// result: the merge counts the item as missing and says so in one line naming the report and the
// field (it merged 1e308 as valid), and the next run redoes the item.
TEST_F(Batch, AReportWithImplausibleFiguresIsRejectedAtTheMerge) {
    write("m.json",
          R"({"items": [{"name": "a", "method": "original", "output": "out/a"},
                        {"name": "b", "method": "original", "output": "out/b"}]})");
    const std::string options = "batch -q --eval-views 1 --eval-resolution 32 ";
    ASSERT_EQ(run(options + manifest()).exit_code, 0);
    const std::string original = test::slurp_existing(path("out/a.animorder.report.json"));
    const nlohmann::json report = nlohmann::json::parse(original);
    ASSERT_TRUE(report["batch"]["ovr_after"].is_number()) << report["batch"];
    ASSERT_GE(report["batch"]["triangles"].get<double>(), 2.0);
    const std::vector<std::pair<std::string, nlohmann::json>> edits = {
        {"ovr_after", 1e308},  {"ovr_after", -1},  {"ovr_before", 0.5},  {"ovr_after", "NaN"},     {"ovr_after", 2000},
        {"acmr_after", 1e308}, {"acmr_before", 0}, {"acmr_after", -0.5}, {"acmr_after", 3.5},      {"triangles", -5},
        {"triangles", 1e308},  {"buffers", 1.5},   {"clips", "two"},     {"index_bytes_added", 7}, {"time_s", -1},
        {"time_s", 1e308},     {"keyframes", -1}};
    for (const auto& [field, value] : edits) {
        nlohmann::json edited = report;
        edited["batch"][field] = value;
        write("out/a.animorder.report.json", edited.dump(2));
        const test::Outcome merged = run(options + "--merge " + manifest());
        const std::string what = field + " = " + value.dump();
        EXPECT_EQ(merged.exit_code, 4) << what << ": " << merged.err;
        EXPECT_EQ(test::line_count(merged.err), 1u) << what << ": " << merged.err;
        EXPECT_NE(merged.err.find("out/a.animorder.report.json was edited: " + field + " is "), std::string::npos)
            << what << ": " << merged.err;
        const nlohmann::json s = nlohmann::json::parse(test::slurp(path("m.summary.json")));
        EXPECT_EQ(s["items"][0]["status"], "missing") << what;
        EXPECT_TRUE(s["items"][0]["ovr_after"].is_null()) << what;
        EXPECT_NE(s["items"][0]["error"].get<std::string>().find(field), std::string::npos) << s["items"][0];
        EXPECT_EQ(s["items"][1]["status"], "ok") << what;
    }
    // Numbers that JSON cannot hold (NaN, Infinity) or a double cannot (1e400): a damaged report.
    const std::string figure = "\"ovr_after\": " + report["batch"]["ovr_after"].dump();
    ASSERT_NE(original.find(figure), std::string::npos) << original;
    for (const char* literal : {"NaN", "Infinity", "1e400", "-1e400"}) {
        std::string damaged = original;
        damaged.replace(damaged.find(figure), figure.size(), std::string("\"ovr_after\": ") + literal);
        write("out/a.animorder.report.json", damaged);
        const test::Outcome merged = run(options + "--merge " + manifest());
        EXPECT_EQ(merged.exit_code, 4) << literal << ": " << merged.err;
        EXPECT_NE(merged.err.find("out/a.animorder.report.json is damaged"), std::string::npos)
            << literal << ": " << merged.err;
        EXPECT_EQ(nlohmann::json::parse(test::slurp(path("m.summary.json")))["items"][0]["status"], "missing");
    }
    // The next run redoes the item (a report the merge refuses is never up to date), and the merge
    // is clean again.
    const test::Outcome again = run(options + manifest());
    EXPECT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("1 done, 1 up to date"), std::string::npos) << again.out;
    const test::Outcome clean = run(options + "--merge " + manifest());
    EXPECT_EQ(clean.exit_code, 0) << clean.err;
    EXPECT_EQ(clean.err, "");
}

// A file that many items read is read and hashed once in a run, not once per item (a dry run over
// 100k items sharing one character re-hashed it 100k times): strace counts the opens of the
// shared glTF's buffer, which only the stamps read, in a dry run over 2000 items. The shared
// digest is each item's own: an item run alone is up to date in the plan of all of them.
TEST_F(Batch, AnInputSharedByManyItemsIsReadOnceInARun) {
    ANIMORDER_REQUIRE_OR_SKIP("strace", run_shell("strace -f -o /dev/null -e trace=openat true").exit_code == 0,
                              "strace is not installed (it counts the opens of the shared input)");
    write("tri.bin", triangle_bytes(0));
    write("tri.gltf", triangle_gltf("tri.bin"));
    // A file changed in the 2 seconds before it is hashed is read again by each item (its times
    // could not yet tell a second change): the plan below reads these once they have settled.
    const auto settled = std::chrono::steady_clock::now() + std::chrono::milliseconds(2200);
    const size_t count = 2000;
    std::string items;
    for (size_t i = 0; i < count; ++i)
        items += std::string(i ? "," : "") + R"({"input": "tri.gltf", "method": "original", "output": "out/i)" +
                 std::to_string(i) + "\"}";
    write("one.json", R"({"items": [{"input": "tri.gltf", "method": "original", "output": "out/i0"}]})");
    ASSERT_EQ(run("batch -q --eval-views 0 " + path("one.json").string()).exit_code, 0);
    write("m.json", "{\"items\": [" + items + "]}");
    std::this_thread::sleep_until(settled);
    // Only the opens stop the program where seccomp filters are there (else every call does).
    const bool filtered = run_shell("strace --seccomp-bpf -f -o /dev/null -e trace=openat true").exit_code == 0;
    const test::Outcome plan =
        run_shell(std::string(filtered ? "strace --seccomp-bpf" : "strace") + " -f -o '" + path("trace.txt").string() +
                  "' -e trace=openat,open " + ANIMORDER_EXE + " batch -q --eval-views 0 --dry-run " + manifest());
    ASSERT_EQ(plan.exit_code, 0) << plan.err;
    const nlohmann::json p = nlohmann::json::parse(plan.out);
    ASSERT_EQ(p["items"].size(), count);
    EXPECT_EQ(p["skip"], 1);
    EXPECT_EQ(p["items"][0]["why"], "up to date");
    EXPECT_EQ(p["items"][1]["why"], "no result yet (not run, or its run did not finish)");
    std::istringstream trace(test::slurp(path("trace.txt")));
    size_t opened = 0;
    for (std::string line; std::getline(trace, line);) opened += line.find("tri.bin\"") != std::string::npos;
    EXPECT_EQ(opened, 1u) << "the shared buffer was opened " << opened << " times for " << count << " items";
}
