// Robustness (docs/ROBUSTNESS.md): every file of the bad-input corpus tests/data/bad/ is refused by
// `sffd deform` with exit status 2, one error line naming the file (and line), no output left and no
// input touched; the odd-but-valid inputs of tests/data/bad/odd/ are processed; option limits, memory
// refusal and fold-over warnings. Big inputs are generated here into a temporary folder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sffd/error.h>
#include "core/job_budget.h"
#include "model/lattice.h"
#include "model/lattice_fold.h"
#include "io/lattice_io.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"
#include "tests/support/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const std::string kSffd = SFFD_BINARY;
const fs::path kBad = fs::path(SFFD_SOURCE_DIR) / "tests/data/bad";
const fs::path kOdd = kBad / "odd";

struct Result {
  int status = -1;
  bool signaled = false;
  std::string out, err;
  long maxRssKiB = 0;
};

using sffd::test::slurp;

// Whether Vulkan's validation layer is installed here, as sffd itself finds it: where it is not (a GPU
// machine with only the driver), asking for it would add sffd's warning to every run's stderr.
bool validationLayerHere() {
  static const bool here = [] {
    const std::string err = sffd::test::runSffd("devices", "SFFD_VK_VALIDATION=1").err;
    return err.find("VK_LAYER_KHRONOS_validation is not installed") == std::string::npos;
  }();
  return here;
}

// A fresh folder per test (tests run in parallel under ctest), removed afterwards.
class Robust : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("sffd_robust_") + info->test_suite_name() + "_" + info->name() + "_" +
                       std::to_string(::getpid()) + "_" + std::to_string(std::random_device{}() % 100000);
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ = fs::temp_directory_path() / name;
    fs::create_directories(dir_ / "out");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Runs sffd (no shell) with `env` added, stdout/stderr captured; wait4 gives the child's peak RSS.
  // SFFD_VK_VALIDATION=1 where the layer is installed: every Vulkan run is under it, whose messages are
  // printed as "sffd: vulkan ..." lines and fail the checks below.
  // leakCheck: a sanitizer build checks leaks too, for runs on --backend cpu only: the device opens while
  // the inputs are read (loadJobAndOpenDevice), and Mesa's drivers leak at exit (scripts/test.sh).
  // fileSizeLimit: the largest file the run may write (RLIMIT_FSIZE, SIGXFSZ ignored): a larger write fails
  // as on a full disk.
  Result runSffd(const std::vector<std::string>& args, const std::vector<std::string>& env = {}, bool leakCheck = false,
                 rlim_t fileSizeLimit = RLIM_INFINITY) {
    fs::path o = dir_ / "stdout", e = dir_ / "stderr";
    const bool validate = validationLayerHere();   // before the fork: it runs sffd itself
    pid_t pid = ::fork();
    if (pid == 0) {
      int fo = ::open(o.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), fe = ::open(e.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fo, 1);
      ::dup2(fe, 2);
      if (validate) ::setenv("SFFD_VK_VALIDATION", "1", 1);
      ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
      if (const char* asan = std::getenv("ASAN_OPTIONS"); asan && leakCheck)
        ::setenv("ASAN_OPTIONS", (std::string(asan) + ":detect_leaks=1").c_str(), 1);
      for (const std::string& kv : env) ::putenv(const_cast<char*>(kv.c_str()));
      if (fileSizeLimit != RLIM_INFINITY) {
        ::signal(SIGXFSZ, SIG_IGN);   // ignored across exec: the write fails with EFBIG instead
        const struct rlimit limit {fileSizeLimit, fileSizeLimit};
        ::setrlimit(RLIMIT_FSIZE, &limit);
      }
      std::vector<char*> argv{const_cast<char*>(kSffd.c_str())};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(kSffd.c_str(), argv.data());
      ::_exit(127);
    }
    Result r;
    int status = 0;
    struct rusage ru {};
    while (::wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
    }
    r.signaled = WIFSIGNALED(status);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.maxRssKiB = ru.ru_maxrss;
    r.out = slurp(o);
    r.err = slurp(e);
    return r;
  }

  std::string out(const std::string& name) const { return (dir_ / "out" / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  // The output folder holds nothing: no result, no temporary file.
  void expectNothingWritten(const std::string& context) {
    for (const auto& f : fs::directory_iterator(dir_ / "out")) ADD_FAILURE() << context << ": left behind " << f.path();
    fs::remove_all(dir_ / "out");
    fs::create_directories(dir_ / "out");
  }

  fs::path dir_;
};

// No sanitizer, validation-layer or crash report on stderr.
void expectNoReports(const Result& r, const std::string& context) {
  for (const char* bad : {"AddressSanitizer", "LeakSanitizer", "runtime error:", "UndefinedBehaviorSanitizer", "sffd: vulkan",
                          "terminate called", "Segmentation fault", "Assertion"})
    EXPECT_EQ(r.err.find(bad), std::string::npos) << context << ": " << bad << " in\n" << r.err;
  EXPECT_FALSE(r.signaled) << context << ": killed by a signal\n" << r.err;
}

// Exit status 2 and exactly one line "sffd: error: <where>..." on stderr, nothing on stdout.
void expectInputError(const Result& r, const std::string& where, const std::string& context) {
  EXPECT_EQ(r.status, 2) << context << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << context << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("sffd: error: " + where, 0), 0u) << context << ": expected 'sffd: error: " << where << "...', got\n" << r.err;
  EXPECT_TRUE(r.out.empty()) << context << "\n" << r.out;
  expectNoReports(r, context);
}

struct Expect {
  int line;             // 0: the message names the file without a line
  const char* reason;   // a word of the message
};

// What each corpus file must say; every file in tests/data/bad/ must be listed (README.md says where each came from).
const std::map<std::string, Expect>& corpusExpectations() {
  static const std::map<std::string, Expect> m = {
      {"binary_junk.obj", {2, "binary data"}},
      {"decimal_comma.obj", {1, "bad number"}},
      {"empty.obj", {0, "empty file"}},
      {"face_two_corners.obj", {4, "at least 3"}},
      {"huge_count.stl", {0, "truncated binary STL"}},
      {"huge_face_count.off", {2, "more than the file can hold"}},
      {"huge_face_count.ply", {0, "truncated"}},
      {"huge_vertex_count.off", {2, "more than the file can hold"}},
      {"huge_vertex_count.om", {0, "truncated"}},
      {"index_huge.obj", {4, "bad vertex index"}},
      {"index_negative.obj", {4, "before the first vertex"}},
      {"index_negative.off", {6, "out of range"}},
      {"index_negative_binary.ply", {0, "out of range"}},
      {"index_out_of_range.obj", {4, "out of range"}},
      {"index_out_of_range.off", {6, "out of range"}},
      {"index_out_of_range.ply", {13, "out of range"}},
      {"index_zero.obj", {4, "index 0"}},
      {"inf_coordinate.off", {4, "non-finite"}},
      {"inf_coordinate_ascii.stl", {6, "non-finite"}},
      {"nan_coordinate.obj", {2, "non-finite"}},
      {"nan_coordinate.ply", {11, "non-finite"}},
      {"nan_coordinate_binary.stl", {0, "non-finite"}},
      {"no_end_header.ply", {4, "end_header"}},
      {"not_off.off", {1, "not an OFF file"}},
      {"only_vertices.obj", {0, "no faces"}},
      {"only_vertices.off", {2, "no faces"}},
      {"overflow_coordinate.obj", {2, "non-finite"}},
      {"png_named.ply", {1, "not a PLY file"}},
      {"truncated.bpt", {11, "file ends"}},
      {"truncated.off", {15, "lists fewer"}},
      {"truncated.om", {0, "damaged"}},
      {"truncated_ascii.stl", {5, "truncated"}},
      {"truncated_binary.ply", {0, "truncated"}},
      {"truncated_binary.stl", {0, "truncated binary STL"}},
      {"truncated_solid_header.stl", {0, "truncated binary STL"}},
      {"unknown_format.xyz", {0, "unknown mesh format"}},
      {"utf16be.off", {0, "UTF-16"}},
      {"utf16le.obj", {0, "UTF-16"}},
      {"lattice_bad_header.npy", {0, "bad .npy header"}},
      {"lattice_degree_ge_counts.json", {4, "counts must exceed the degree"}},
      {"lattice_degree_too_high.json", {3, "1..5"}},
      {"lattice_empty.prm", {0, "empty file"}},
      {"lattice_huge_counts.json", {4, "too large"}},
      {"lattice_huge_shape.npy", {0, "too large"}},
      {"lattice_index_out_of_range.prm", {17, "out of range"}},
      {"lattice_int_dtype.npy", {0, "dtype"}},
      {"lattice_inverted_box.json", {5, "box.max must exceed box.min"}},
      {"lattice_knots_non_monotone.json", {6, "non-decreasing"}},
      {"lattice_knots_too_short.json", {6, "counts+degree+1"}},
      {"lattice_missing_box_info.prm", {0, "missing section [Box info]"}},
      {"lattice_missing_format.json", {0, "missing field \"format\""}},
      {"lattice_missing_key.prm", {1, "missing key 'box length y'"}},
      {"lattice_missing_weights.prm", {0, "missing section [Parameters weights]"}},
      {"lattice_nan.npy", {0, "not finite"}},
      {"lattice_nan_control_point.json", {20, "syntax error"}},
      {"lattice_nan_weight.prm", {16, "non-finite"}},
      {"lattice_overflow_control_point.json", {11, "overflow"}},
      {"lattice_too_many_points.prm", {2, "2..6"}},
      {"lattice_truncated.json", {8, "syntax error"}},
      {"lattice_truncated.npy", {0, "truncated"}},
      {"lattice_unknown_field.json", {3, "unknown field"}},
      {"lattice_key_with_newline.json", {3, "unknown field \"control?points\""}},
      {"lattice_wrong_point_count.json", {6, "need 27"}},
      {"lattice_wrong_shape.npy", {0, "shape"}},
      {"lattice_zero_length.prm", {7, "must be positive"}},
      {"lattice_zero_size_box.json", {5, "zero-size"}},
  };
  return m;
}

bool isLatticeFile(const fs::path& p) {
  std::string ext = p.extension().string();
  return ext == ".json" || ext == ".prm" || ext == ".npy";
}

// The corpus files (and the fuzzers' regression files under fuzz/), each tried as a mesh or as a lattice.
std::vector<fs::path> corpusFiles() {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(kBad)) {
    if (!e.is_regular_file()) continue;
    fs::path rel = fs::relative(e.path(), kBad);
    std::string top = rel.begin()->string();
    if (top == "odd" || rel == "README.md" || rel == "generate.py") continue;
    files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST_F(Robust, EveryCorpusFileIsRefused) {
  const std::string mesh = (kOdd / "partly_outside.obj").string(), lattice = (kOdd / "lattice_small_box_extrapolate.json").string();
  std::vector<fs::path> files = corpusFiles();
  ASSERT_GE(files.size(), 60u);
  std::set<std::string> seen;
  for (const fs::path& f : files) {
    fs::path rel = fs::relative(f, kBad);
    const bool fromFuzzer = rel.begin()->string() == "fuzz";
    const std::string before = slurp(f);
    const auto mtime = fs::last_write_time(f);
    const bool asLattice = isLatticeFile(f);   // fuzz regression files keep the extension of the reader that failed
    std::vector<std::string> args = {"deform", asLattice ? mesh : f.string(), "-l", asLattice ? f.string() : lattice,
                                     "--method", "classic", "--backend", "cpu", "-o", out("result.obj")};
    Result r = runSffd(args, {}, /*leakCheck=*/true);
    std::string where = f.string();
    if (!fromFuzzer) {
      auto it = corpusExpectations().find(rel.string());
      if (it == corpusExpectations().end()) {
        ADD_FAILURE() << rel << " is not in corpusExpectations() (and README.md): say what it must report";
        continue;
      }
      seen.insert(rel.string());
      where += it->second.line ? ":" + std::to_string(it->second.line) + ": " : ": ";
      EXPECT_NE(r.err.find(it->second.reason), std::string::npos) << rel << ": expected '" << it->second.reason << "' in\n" << r.err;
    }
    expectInputError(r, where, rel.string());
    expectNothingWritten(rel.string());
    EXPECT_EQ(slurp(f), before) << rel << " was modified";
    EXPECT_EQ(fs::last_write_time(f), mtime) << rel << " was touched";
  }
  for (const auto& [name, e] : corpusExpectations()) EXPECT_TRUE(seen.count(name)) << name << " is listed but missing from " << kBad;
}

// Counts in a header far beyond the file's size are refused before anything is allocated: the
// process stays small (peak RSS well under the gigabytes the counts ask for).
TEST_F(Robust, HugeHeaderCountsAllocateNothing) {
  const std::string lattice = (kOdd / "lattice_small_box_extrapolate.json").string();
  std::string tri = "0 0 0\n1 0 0\n0 1 0\n";
  struct Case { std::string name, bytes; };
  std::string stl(84, '\0');
  std::memcpy(stl.data(), "binary", 6);
  uint32_t n = 0xFFFFFFFFu;
  std::memcpy(stl.data() + 80, &n, 4);
  stl += std::string(50, '\0');
  std::vector<Case> cases = {
      {"faces.off", "OFF\n3 2147483647 0\n" + tri + "3 0 1 2\n"},
      {"vertices.off", "OFF\n4294967295 1 0\n" + tri + "3 0 1 2\n"},
      {"elements.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty double x\nproperty double y\n"
                       "property double z\nelement face 4294967295\nproperty list uint int vertex_indices\nend_header\n" +
                           std::string(64, '\x01')},
      {"list.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n" +
                       std::string(36, '\0') + std::string("\xff\xff\xff\x7f", 4) + std::string(12, '\0')},
      {"ascii_list.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uint int vertex_indices\nend_header\n" + tri + "2000000000 0 1 2\n"},
      {"count.stl", stl},
      {"patches.bpt", "2000000000\n3 3\n0 0 0\n"},
  };
  for (const Case& c : cases) {
    std::string p = write(c.name, c.bytes);
    Result r = runSffd({"deform", p, "-l", lattice, "--method", "classic", "--backend", "cpu", "-o", out("o.obj")}, {}, true);
    expectInputError(r, p, c.name);
    EXPECT_LT(r.maxRssKiB, 400 * 1024) << c.name << ": peak RSS " << r.maxRssKiB << " KiB";
    expectNothingWritten(c.name);
  }
  // The same for lattices: counts and shapes far beyond the file.
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (256, 256, 256, 3), }\n";
  std::string npy = std::string("\x93NUMPY\x01\x00", 8);
  npy += char(header.size() & 0xff);
  npy += char(header.size() >> 8);
  npy += header + std::string(24, '\0');
  std::string lat = write("big.npy", npy);
  Result r = runSffd({"deform", (kOdd / "partly_outside.obj").string(), "-l", lat, "--method", "classic", "-o", out("o.obj")});
  expectInputError(r, lat, "big.npy");
  EXPECT_LT(r.maxRssKiB, 400 * 1024);
  expectNothingWritten("big.npy");
}

// A 100,000-character line: refused with its line number when it is garbage, read when it is a comment.
TEST_F(Robust, HundredThousandCharacterLine) {
  const std::string lattice = (kOdd / "lattice_small_box_extrapolate.json").string();
  std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::string longGarbage = "v 0 0 " + std::string(100000, '7') + "x\n";
  std::string p = write("long.obj", tri + longGarbage + "f 1 2 3\n");
  Result r = runSffd({"deform", p, "-l", lattice, "--method", "classic", "-o", out("o.obj")});
  expectInputError(r, p + ":4: ", "long garbage line");
  EXPECT_LT(r.err.size(), 400u) << "the message quotes a bounded part of the token";
  expectNothingWritten("long garbage line");

  std::string face = "f";
  for (int i = 0; i < 20000; ++i) face += " 1";   // a 40,001-character face line with 20,000 corners: valid, no area
  std::string q = write("long_ok.obj", tri + "# " + std::string(100000, 'c') + "\n" + face + "\nf 1 2 3\n");
  r = runSffd({"deform", q, "-l", lattice, "--method", "classic", "-o", out("o.obj"), "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  expectNoReports(r, "long comment line");
  EXPECT_NE(r.err.find("sffd: warning: 1 polygon without area dropped"), std::string::npos) << r.err;
  sffd::Mesh m = sffd::readMesh(out("o.obj"));
  EXPECT_EQ(m.triangles.size(), 1u);   // the polygon without area is dropped, not fanned into 19,998 slivers
  fs::remove(out("o.obj"));

  std::string ply = "ply\nformat ascii 1.0\ncomment " + std::string(100000, 'p') + "\nelement vertex 3\nproperty float x\n";
  std::string pp = write("long.ply", ply + "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                           "end_header\n0 0 0\n1 0 0\n0 " + std::string(100000, '1') + " 0\n3 0 1 2\n");
  r = runSffd({"deform", pp, "-l", lattice, "--method", "classic", "-o", out("p.obj"), "--quiet"});
  expectInputError(r, pp + ":13: ", "long PLY number");
  expectNothingWritten("long PLY number");
}

// Options that size the job, output paths that are unwritable or are an input.
TEST_F(Robust, OptionsAndOutputPathsAreChecked) {
  const std::string mesh = (kOdd / "partly_outside.obj").string(), lattice = (kOdd / "lattice_small_box_extrapolate.json").string();
  // The inputs are copied so that links to them can be made here.
  std::string m = (dir_ / "m.obj").string(), l = (dir_ / "l.json").string();
  fs::copy_file(mesh, m);
  fs::copy_file(lattice, l);
  const std::string mBytes = slurp(m), lBytes = slurp(l);
  fs::create_hard_link(m, dir_ / "hard.obj");
  fs::create_symlink(m, dir_ / "sym.obj");
  write("file", "a regular file");
  std::vector<std::string> base = {"deform", m, "-l", l, "--method", "classic"};
  struct Case { std::vector<std::string> extra; std::string where; };
  std::vector<Case> cases = {
      {{"--tess", "0", "-o", out("o.obj")}, "--tess must be an integer 1..64"},
      {{"--tess", "65", "-o", out("o.obj")}, "--tess must"},
      {{"--tess", "-3", "-o", out("o.obj")}, "--tess must"},
      {{"--tess", "99999999999999999999", "-o", out("o.obj")}, "--tess must"},
      {{"--tess", "1.5", "-o", out("o.obj")}, "--tess must"},
      {{"--edge-length", "0", "-o", out("o.obj")}, "--edge-length must be a finite length > 0"},
      {{"--edge-length", "-1", "-o", out("o.obj")}, "--edge-length must"},
      {{"--edge-length", "nan", "-o", out("o.obj")}, "--edge-length must"},
      {{"--edge-length", "inf", "-o", out("o.obj")}, "--edge-length must"},
      {{"--edge-length", "1e999", "-o", out("o.obj")}, "--edge-length must"},
      // Values the job would have taken as another (--samples -1 ran as the default) or ignored.
      {{"--samples", "-1", "-o", out("o.obj")}, "option --samples needs an integer 1..15 (below 3 samples as 3), not '-1'"},
      {{"--samples", "0", "-o", out("o.obj")}, "option --samples needs"},
      {{"--samples", "16", "-o", out("o.obj")}, "option --samples needs"},
      {{"--degree", "3", "-o", out("o.obj")}, "--degree is a .npy lattice's; " + l + " keeps its own"},
      {{"-o", m}, m + ": output path is an input"},
      {{"-o", (dir_ / "." / "m.obj").string()}, (dir_ / "." / "m.obj").string() + ": output path is an input"},
      {{"-o", (dir_ / "out" / ".." / "m.obj").string()}, (dir_ / "out" / ".." / "m.obj").string() + ": output path is an input"},
      {{"-o", (dir_ / "hard.obj").string()}, (dir_ / "hard.obj").string() + ": output path is an input"},
      {{"-o", (dir_ / "sym.obj").string()}, (dir_ / "sym.obj").string() + ": output path is an input"},
      {{"-o", l}, l + ": output path is an input"},
      {{"-o", out("o.obj"), "--stats", m}, m + ": output path is an input"},
      {{"-o", out("o.obj"), "--patches", out("p.txt")}, "--patches needs --method smooth"},   // o.obj was left written
      // A --stats that cannot be written once the output is: the output goes (it stayed), a .gltf's .bin too.
      {{"-o", out("o.obj"), "--stats", "/proc/sffd-robustness.json"}, "/proc/sffd-robustness.json: cannot write"},
      {{"-o", out("o.gltf"), "--stats", "/proc/sffd-robustness.json"}, "/proc/sffd-robustness.json: cannot write"},
      {{"-o", (dir_ / "file" / "o.obj").string()}, (dir_ / "file" / "o.obj").string() + ": cannot write"},
      {{"-o", (dir_ / "no" / "such" / "o.obj").string()}, (dir_ / "no" / "such" / "o.obj").string() + ": cannot write"},
      {{"-o", (dir_ / "out").string() + "/"}, ""},
      {{"-o", out("o.xyz")}, out("o.xyz") + ": cannot write mesh format"},
      {{"-o", "/proc/sffd-robustness.obj"}, "/proc/sffd-robustness.obj: cannot write"},
      // Longer than a file name may be: an exit status 1 and a raw std::filesystem message once.
      {{"-o", out(std::string(300, 'n') + ".obj")}, out(std::string(300, 'n') + ".obj") + ": cannot write: File name too long"},
      {{"-o", out(std::string(300, 'n') + ".ply")}, out(std::string(300, 'n') + ".ply") + ": cannot write"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    std::string context;
    for (const auto& a : c.extra) context += a + " ";
    Result r = runSffd(args);
    expectInputError(r, c.where, context);
    expectNothingWritten(context);
    EXPECT_EQ(slurp(m), mBytes) << context;
    EXPECT_EQ(slurp(l), lBytes) << context;
  }
  // --stats and --patches at one path: the patches were overwritten by the statistics.
  Result sp = runSffd({"deform", m, "-l", l, "--tess", "2", "-o", out("o.obj"), "--patches", out("x.txt"), "--stats", out("x.txt")});
  expectInputError(sp, out("x.txt") + ": output path is an input file", "--stats onto --patches");
  expectNothingWritten("--stats onto --patches");
  // An output that is no regular file (a FIFO; /dev/stdout through its link) is refused: renamed into place,
  // the output removed it (as root, /dev/stdout itself) and wrote nothing there.
  ASSERT_EQ(::mkfifo((dir_ / "fifo.json").c_str(), 0644), 0);
  Result ff = runSffd({"deform", m, "-l", l, "--method", "classic", "-o", out("o.obj"), "--stats", (dir_ / "fifo.json").string()});
  expectInputError(ff, (dir_ / "fifo.json").string() + ": cannot write: not a regular file", "FIFO");
  expectNothingWritten("FIFO");
  EXPECT_TRUE(fs::is_fifo(dir_ / "fifo.json"));
  // clip likewise: its --stats comes after its output.
  Result c = runSffd({"clip", m, "-l", l, "--backend", "cpu", "-o", out("c.obj"), "--stats", "/proc/sffd-robustness.json"});
  expectInputError(c, "/proc/sffd-robustness.json: cannot write", "clip --stats");
  expectNothingWritten("clip --stats");
  EXPECT_TRUE(fs::is_symlink(dir_ / "sym.obj"));
  EXPECT_FALSE(fs::exists(dir_ / "file" / "o.obj"));
  EXPECT_FALSE(fs::exists("/proc/sffd-robustness.obj"));
  // A file name with a newline: still one line.
  Result n = runSffd({"deform", (dir_ / "no\nsuch.obj").string(), "-l", l, "--method", "classic", "-o", out("o.obj")});
  expectInputError(n, (dir_ / "no?such.obj").string() + ": cannot read", "newline in a file name");
  // A directory given as the mesh.
  Result r = runSffd({"deform", (dir_ / "out").string(), "-l", l, "--method", "classic", "-o", out("o.obj")});
  expectInputError(r, (dir_ / "out").string() + ": ", "directory as mesh");
  // Inputs that are no regular file: a FIFO nobody writes to (its open blocked for ever) as the mesh or the
  // lattice, and a device (read as an empty file before).
  ASSERT_EQ(::mkfifo((dir_ / "fifo.obj").c_str(), 0644), 0);
  const std::string notRegular = ": cannot read: not a regular file (a FIFO, socket or device)";
  r = runSffd({"deform", (dir_ / "fifo.obj").string(), "-l", l, "-o", out("o.obj")});
  expectInputError(r, (dir_ / "fifo.obj").string() + notRegular, "FIFO as mesh");
  r = runSffd({"deform", m, "-l", (dir_ / "fifo.json").string(), "-o", out("o.obj")});
  expectInputError(r, (dir_ / "fifo.json").string() + notRegular, "FIFO as lattice");
  fs::create_symlink("/dev/zero", dir_ / "zero.stl");
  r = runSffd({"deform", (dir_ / "zero.stl").string(), "-l", l, "-o", out("o.obj")});
  expectInputError(r, (dir_ / "zero.stl").string() + notRegular, "device as mesh");
  expectNothingWritten("inputs that are no regular file");
  // Valid sizes still run.
  r = runSffd({"deform", m, "-l", l, "--method", "classic", "--tess", "64", "--edge-length", "0.5", "-o", out("o.obj"), "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out("o.obj")));
  // A name of the longest length a file may have (255 bytes) is written: its temporary beside it was longer.
  for (const char* ext : {".obj", ".ply"}) {
    const std::string longest = out(std::string(255 - 4, 'n') + ext);
    r = runSffd({"deform", m, "-l", l, "-o", longest, "--quiet"});
    EXPECT_EQ(r.status, 0) << ext << "\n" << r.err;
    EXPECT_TRUE(fs::exists(longest)) << ext;
  }
}

// A small file that cannot be written once the output has replaced the user's file (a --stats in /proc passes
// the checks made before the work, as a full disk or a folder removed during the run would): every file the
// command replaced is as it was, a link stays a link, and nothing new is left. The output was taken away.
TEST_F(Robust, AFailedCommandPutsBackTheFilesItReplaced) {
  const std::string m = (kOdd / "partly_outside.obj").string(), l = (kOdd / "lattice_small_box_extrapolate.json").string();
  const std::string bad = "/proc/sffd-robustness.json";
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> replaced;   // files in out/ the user had
  };
  const std::vector<std::string> deform = {"deform", m, "-l", l, "--backend", "cpu", "--tess", "2"};
  const std::vector<Case> cases = {
      {{"--method", "classic", "-o", out("o.obj"), "--stats", bad}, {"o.obj"}},
      {{"--method", "classic", "-o", out("o.gltf"), "--stats", bad}, {"o.gltf", "o.bin"}},
      {{"-o", out("o.ply"), "--stats", bad}, {"o.ply"}},   // smooth into a .ply: streamed as it is made
      {{"-o", out("o.ply"), "--patches", out("p.txt"), "--stats", bad}, {"o.ply", "p.txt"}},
      {{"-o", out("o.ply"), "--patches", out("p.txt"), "--stats", bad}, {"p.txt"}},   // the output is new
      {{"--method", "classic", "-o", out("link.obj"), "--stats", bad}, {"target.obj"}},
      {{"clip"}, {"c.obj"}},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = deform;
    if (c.args[0] == "clip") args = {"clip", m, "-l", l, "--backend", "cpu", "-o", out("c.obj"), "--stats", bad};
    else args.insert(args.end(), c.args.begin(), c.args.end());
    std::string context;
    for (const auto& a : args) context += a + " ";
    for (const std::string& f : c.replaced) std::ofstream(out(f)) << "the user's " << f;
    if (c.replaced[0] == "target.obj") fs::create_symlink("target.obj", out("link.obj"));
    expectInputError(runSffd(args), bad + ": cannot write", context);
    for (const std::string& f : c.replaced) {
      EXPECT_EQ(slurp(out(f)), "the user's " + f) << context;
      fs::remove(out(f));
    }
    if (c.replaced[0] == "target.obj") {
      EXPECT_TRUE(fs::is_symlink(out("link.obj"))) << context;
      fs::remove(out("link.obj"));
    }
    expectNothingWritten(context);
  }
}

// A job above the memory limit is refused before the GPU work, with the numbers.
TEST_F(Robust, JobAboveTheMemoryLimitIsRefused) {
  const std::string mesh = (kOdd / "polygon_1000.obj").string(), lattice = (kOdd / "lattice_small_box_extrapolate.json").string();
  Result r = runSffd({"deform", mesh, "-l", lattice, "--method", "classic", "-o", out("o.obj")}, {"SFFD_MEMORY_LIMIT=64K"});
  expectInputError(r, "the job needs about ", "memory limit");
  EXPECT_NE(r.err.find("more than the limit of 64.00 KiB (SFFD_MEMORY_LIMIT)"), std::string::npos) << r.err;
  expectNothingWritten("memory limit");
  r = runSffd({"deform", mesh, "-l", lattice, "--method", "classic", "-o", out("o.obj")}, {"SFFD_MEMORY_LIMIT=lots"});
  expectInputError(r, "SFFD_MEMORY_LIMIT must be a size", "bad limit");
  expectNothingWritten("bad limit");
  r = runSffd({"deform", mesh, "-l", lattice, "--method", "classic", "-o", out("o.obj"), "--quiet"}, {"SFFD_MEMORY_LIMIT=1G"});
  EXPECT_EQ(r.status, 0) << r.err;
}

// A write that fails half way (a full disk; here a file size limit of 256 KiB) stops a streamed job at the
// next piece, whose file is formatted and written on a thread of its own (MeshFileWriter): one error line,
// exit status 2, neither the output nor a temporary file left; so does a gathered format.
TEST_F(Robust, AFailedWriteStopsTheJobAndLeavesNothing) {
  const std::string mesh = (fs::path(SFFD_SOURCE_DIR) / "tests/data/teapot_8x8.obj").string(), lattice = (dir_ / "l.json").string();
  ASSERT_EQ(runSffd({"lattice", mesh, "-o", lattice, "--preset", "twist:0.3", "--quiet"}).status, 0);
  for (const char* backend : {"cpu", "vulkan"}) {
    if (!sffd::test::hasDevice(backend)) continue;
    for (const char* name : {"o.ply", "o.stl", "o.obj"})
      for (const bool binary : {true, false}) {
        if (binary && std::string(name) == "o.obj") continue;
        std::vector<std::string> args = {"deform", mesh, "-l", lattice, "--backend", backend, "-o", out(name)};
        if (binary) args.push_back("--binary");
        const std::string context = std::string(backend) + " " + name + (binary ? " binary" : "");
        const Result r = runSffd(args, {}, false, 256 * 1024);
        // lavapipe of Mesa 25.0 keeps device memory in a file, which the limit also holds: then the job
        // stops before it writes, with a device error that names the limit (vk_device.cpp), never a SIGBUS.
        if (std::string(backend) == "vulkan" && r.err.find("without memory behind it") != std::string::npos) {
          EXPECT_EQ(r.status, 3) << context << "\n" << r.err;
          EXPECT_EQ(r.err.rfind("sffd: error: Vulkan: the driver gave a buffer of ", 0), 0u) << context << "\n" << r.err;
          EXPECT_NE(r.err.find("(ulimit -f: 256 KiB)"), std::string::npos) << context << "\n" << r.err;
          EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << context << "\n" << r.err;
        } else {
          expectInputError(r, out(name) + ": cannot write: ", context);
        }
        expectNoReports(r, context);
        expectNothingWritten(context);
      }
  }
}

// ---------------------------------------------------------------------------------------------------
// Odd but valid inputs are processed.

std::vector<std::string> oddMeshes() {
  std::vector<std::string> r;
  for (const auto& e : fs::directory_iterator(kOdd)) {
    std::string ext = e.path().extension().string();
    if (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl" || ext == ".om") r.push_back(e.path().filename().string());
  }
  std::sort(r.begin(), r.end());
  return r;
}

bool allFinite(const sffd::Mesh& m) {
  for (const auto& p : m.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  for (const auto& n : m.normals)
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) return false;
  return true;
}

class RobustOdd : public Robust, public ::testing::WithParamInterface<std::string> {};

// Each odd mesh: a lattice fitted to it and twisted, then deformed on Vulkan (validation layer on) and
// on the CPU reference; classic: same triangles as read, finite results, no warning, the input untouched.
// And by every method that makes patches (the default, smooth, and accurate), in fast and strict float, and
// in fast float at --tess 1, 2 and 7 (scripts/odd_sweep.sh sweeps more options, outside CI):
// a written, finite result (degenerate triangles between opposite corner normals gave NaN normals, which
// no writer accepts, until snormalize left a vector without a direction as it is).
TEST_P(RobustOdd, IsProcessed) {
  const std::string mesh = (kOdd / GetParam()).string();
  const std::string before = slurp(mesh);
  sffd::Mesh in = sffd::readMesh(mesh);
  std::string lat = (dir_ / "fit.json").string();
  Result r = runSffd({"lattice", mesh, "-o", lat, "--preset", "twist:0.5", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* backend : {"vulkan", "cpu"}) {
    std::string o = out(std::string(backend) + ".ply");
    r = runSffd({"deform", mesh, "-l", lat, "--method", "classic", "--backend", backend, "-o", o, "--quiet"});
    ASSERT_EQ(r.status, 0) << backend << "\n" << r.err;
    EXPECT_TRUE(r.err.empty()) << backend << "\n" << r.err;
    expectNoReports(r, backend);
    sffd::Mesh res = sffd::readMesh(o);
    EXPECT_EQ(res.triangles.size(), in.triangles.size()) << backend;
    EXPECT_EQ(res.positions.size(), in.positions.size()) << backend;
    EXPECT_TRUE(allFinite(res)) << backend;
    for (const char* method : {"smooth", "accurate"})
      for (const bool strict : {false, true}) {
        const std::string context = std::string(backend) + " " + method + (strict ? " strict" : "");
        std::vector<std::string> args = {"deform", mesh, "-l", lat, "--method", method, "--backend", backend, "--tess", "3", "-o", o, "--quiet"};
        if (strict) args.push_back("--strict");
        r = runSffd(args);
        ASSERT_EQ(r.status, 0) << context << "\n" << r.err;
        expectNoReports(r, context);
        EXPECT_TRUE(allFinite(sffd::readMesh(o))) << context;
      }
    // Every other kind of tessellation level: the fewest sub-triangles (1), an even one, an odd one above 3.
    for (const char* method : {"smooth", "accurate"})
      for (const char* tess : {"1", "2", "7"}) {
        const std::string context = std::string(backend) + " " + method + " --tess " + tess;
        r = runSffd({"deform", mesh, "-l", lat, "--method", method, "--backend", backend, "--tess", tess, "-o", o, "--quiet"});
        ASSERT_EQ(r.status, 0) << context << "\n" << r.err;
        expectNoReports(r, context);
        EXPECT_TRUE(allFinite(sffd::readMesh(o))) << context;
      }
  }
  EXPECT_EQ(slurp(mesh), before);
}

INSTANTIATE_TEST_SUITE_P(Robust, RobustOdd, ::testing::ValuesIn(oddMeshes()), [](const auto& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

// Vertices outside the lattice box: unmoved with "outside": "keep", moved continuously (finite) with
// "extrapolate"; inside vertices agree between the two.
TEST_F(Robust, PartlyOutsideTheBoxFollowsTheOutsideRule) {
  const std::string mesh = (kOdd / "partly_outside.obj").string();
  sffd::Mesh in = sffd::readMesh(mesh);
  std::map<std::string, sffd::Mesh> res;
  for (const char* mode : {"keep", "extrapolate"}) {
    std::string o = out(std::string(mode) + ".ply");
    Result r = runSffd({"deform", mesh, "-l", (kOdd / ("lattice_small_box_" + std::string(mode) + ".json")).string(), "--method", "classic",
                  "-o", o, "--quiet"});
    ASSERT_EQ(r.status, 0) << r.err;
    res[mode] = sffd::readMesh(o);
    ASSERT_EQ(res[mode].positions.size(), in.positions.size());
    EXPECT_TRUE(allFinite(res[mode]));
  }
  size_t outside = 0;
  for (size_t v = 0; v < in.positions.size(); ++v) {
    const glm::dvec3& p = in.positions[v];
    bool inside = std::abs(p.x) <= 0.5 && std::abs(p.y) <= 0.5 && std::abs(p.z) <= 0.5;
    if (inside) {
      EXPECT_NEAR(glm::length(res["keep"].positions[v] - res["extrapolate"].positions[v]), 0, 1e-12);
    } else {
      ++outside;
      EXPECT_EQ(res["keep"].positions[v], p) << "vertex " << v;
      EXPECT_GT(glm::length(res["extrapolate"].positions[v] - p), 1e-3) << "vertex " << v;
    }
  }
  EXPECT_EQ(outside, 8u);
}

// A lattice that folds over (or is mirrored) is used, with one warning line.
TEST_F(Robust, FoldingLatticeWarnsOnce) {
  const std::string mesh = (kOdd / "partly_outside.obj").string();
  for (const char* name : {"lattice_folding.json", "lattice_mirrored.json"}) {
    std::string lat = (kOdd / name).string();
    Result r = runSffd({"deform", mesh, "-l", lat, "--method", "classic", "-o", out("o.obj"), "--quiet"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("sffd: warning: lattice " + lat + (std::string(name) == "lattice_folding.json" ? " folds over" : " is mirrored"), 0), 0u)
        << r.err;
    expectNoReports(r, name);
    EXPECT_TRUE(fs::exists(out("o.obj")));
  }
  // A lattice that does not fold says nothing of folding; this small one leaves most of the mesh
  // outside its box, which is said once.
  const std::string keep = (kOdd / "lattice_small_box_keep.json").string();
  Result r = runSffd({"deform", mesh, "-l", keep, "--method", "classic", "-o", out("k.obj"), "--quiet"});
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.err, "sffd: warning: 89% of the mesh's vertices lie outside the box of lattice " + keep + ": they are left unmoved\n");
}

// ---------------------------------------------------------------------------------------------------
// The checks as functions.

TEST(RobustFold, IdentityAndPresetsAreCleanFoldsAreSeen) {
  using namespace sffd;
  for (std::array<int, 3> degree : {std::array<int, 3>{1, 1, 1}, {2, 2, 2}, {3, 1, 5}}) {
    Lattice L = makeIdentityLattice({-1, -2, -3}, {1, 2, 3}, {7, 6, 8}, degree);
    FoldCheck c = checkLatticeFold(packLattice(L));
    EXPECT_TRUE(c.clean());
    EXPECT_EQ(c.boxesChecked, c.boxes);
    EXPECT_EQ(c.samples, 27 * c.boxes);
    EXPECT_NEAR(c.minRatio, 1, 1e-9);
    EXPECT_NEAR(c.maxRatio, 1, 1e-9);
    EXPECT_EQ(foldWarning(c, "x"), "");
    for (const char* preset : {"twist", "bend", "taper", "bulge"}) {
      Lattice T = L;
      applyLatticePreset(T, preset, 1.0);
      EXPECT_TRUE(checkLatticeFold(packLattice(T)).clean()) << preset;
    }
    // Swap two neighbouring layers of control points along x: folds.
    Lattice F = L;
    for (int j = 0; j < F.counts[1]; ++j)
      for (int k = 0; k < F.counts[2]; ++k) std::swap(F.controlPoints[F.index(2, j, k)], F.controlPoints[F.index(4, j, k)]);
    FoldCheck f = checkLatticeFold(packLattice(F));
    EXPECT_TRUE(f.folds());
    EXPECT_NE(foldWarning(f, "x").find("folds over"), std::string::npos);
    // All layers in reverse order: mirrored everywhere.
    Lattice M = L;
    for (auto& p : M.controlPoints) p.x = -p.x;
    EXPECT_TRUE(checkLatticeFold(packLattice(M)).mirrored());
    // A flattened layer: collapses.
    Lattice Z = L;
    for (auto& p : Z.controlPoints) p.z = 0;
    EXPECT_TRUE(checkLatticeFold(packLattice(Z)).collapses());
  }
  // A rotated, left-handed frame reads as clean when undeformed.
  Lattice R = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {4, 4, 4}, {2, 2, 2});
  R.frameLinear = glm::dmat3(0, 1, 0, 1, 0, 0, 0, 0, 2);   // swaps x and y: det < 0
  setIdentityControlPoints(R);
  EXPECT_TRUE(checkLatticeFold(packLattice(R)).clean());
  // Boxes 2^-400 and 2^400 across, native and framed: the ratio is parameters per parameter, the same at
  // every size (det J_R and det A alone, cubes of lengths, left double's range: "collapses" below about
  // 1e-100, NaN above 1e100).
  for (int k : {-400, 400}) {
    const double size = std::ldexp(1.0, k);
    Lattice native = makeIdentityLattice({-size, -size, -size}, {size, size, size}, {5, 5, 5}, {2, 2, 2});
    applyLatticePreset(native, "twist", 0.5);
    Lattice framed = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {5, 5, 5}, {2, 2, 2});
    framed.frameLinear = glm::dmat3(1 / size);
    // The identity by hand: the frame's determinant (2^-+1200) leaves double's range, so glm::inverse (and
    // setIdentityControlPoints, which refuses such a frame as singular, as validateLattice does) cannot.
    for (glm::dvec3& p : framed.controlPoints) p *= size;
    for (const Lattice* lattice : {&native, &framed}) {
      const FoldCheck c = checkLatticeFold(packLattice(*lattice));
      EXPECT_TRUE(c.clean()) << k << foldWarning(c, "x");
      EXPECT_GT(c.minRatio, 0.1) << k;
    }
  }
  // A small budget: every box's 27 samples, on an even stride of boxes.
  Lattice B = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {16, 16, 16}, {2, 2, 2});
  FoldCheck s = checkLatticeFold(packLattice(B), 10000);
  EXPECT_LT(s.boxesChecked, s.boxes);
  EXPECT_GT(s.boxesChecked, 0u);
  EXPECT_TRUE(s.clean());
}

TEST(RobustBudget, SizeOptionsAndEstimates) {
  using namespace sffd;
  EXPECT_NO_THROW(checkSizeOptions(std::nullopt, std::nullopt));
  EXPECT_NO_THROW(checkSizeOptions(std::string("1e-3"), std::string("1")));
  EXPECT_NO_THROW(checkSizeOptions(std::string("2"), std::to_string(kMaxTessLevel)));
  for (const char* bad : {"0", "-0", "-1", "nan", "inf", "", "x", "1e999", "1.0x"}) EXPECT_THROW(checkSizeOptions(std::string(bad), std::nullopt), Error) << bad;
  for (const char* bad : {"0", "65", "-1", "", "2.5", "99999999999999999999999"})
    EXPECT_THROW(checkSizeOptions(std::nullopt, std::string(bad)), Error) << bad;

  Mesh m;
  m.positions.assign(1000000, glm::dvec3(0));
  m.normals.assign(1000000, glm::dvec3(0, 0, 1));
  m.weldId.assign(1000000, 0);
  m.triangles.assign(2000000, {0, 1, 2});
  PackedLattice P = packLattice(makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {5, 5, 5}, {2, 2, 2}));
  DeviceLimits lim;   // lavapipe's: 128 MiB a binding
  JobEstimate cpu = estimateClassicJob(m, P, 8, nullptr), gpu = estimateClassicJob(m, P, 8, &lim);
  EXPECT_GT(cpu.hostBytes, 2 * (52 + 12 * 2) * 1000000ull);   // input and output meshes at least
  EXPECT_LT(cpu.hostBytes, 1000ull * 1000000);
  EXPECT_EQ(cpu.deviceBytes, 0u);
  EXPECT_EQ(gpu.chunkVertices, 1000000u);
  EXPECT_EQ(gpu.chunks, 1u);
  EXPECT_GT(gpu.deviceBytes, 4 * 32 * 1000000ull);
  lim.maxStorageBufferRange = 1 << 20;   // 1 MiB: 32768 double vertices a chunk
  JobEstimate small = estimateClassicJob(m, P, 8, &lim);
  EXPECT_EQ(small.chunkVertices, 32768u);
  EXPECT_EQ(small.chunks, (1000000u + 32767) / 32768);
  EXPECT_EQ(small.deviceBytes, gpu.deviceBytes);   // chunks change the dispatches, not what stays on the device
  // The lattice coefficients are one binding: above the range, the job cannot fit.
  lim.maxStorageBufferRange = 1024;
  EXPECT_THROW(checkJobFits(estimateClassicJob(m, P, 8, &lim), P, 8, &lim, 0), Error);
  EXPECT_GT(hostMemoryLimit(0), 0u);
  EXPECT_EQ(hostMemoryLimit(12345), 12345u);
  EXPECT_EQ(parseByteSize("1.5K"), 1536u);
  EXPECT_EQ(parseByteSize("lots"), 0u);
  EXPECT_EQ(formatBytes(1536), "1.50 KiB");
}

}  // namespace
