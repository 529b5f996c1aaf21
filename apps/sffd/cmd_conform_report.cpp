// sffd conform: comparing the backends' buffers pair by pair, the baseline of expected failures, and
// the reports: the contract's text lines, JUnit XML and JSON (docs/CLI.md, docs/CONFORMANCE.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>
#include <sffd/error.h>

#include "apps/sffd/conform.h"
#include "io/atomic_file.h"

namespace sffd::cli::conform {

using json = nlohmann::ordered_json;

const char* statusName(Status s) {
  static const char* names[] = {"Pass", "Fail", "Skip", "Crash", "Timeout", "ExpectedFail", "UnexpectedPass"};
  return names[int(s)];
}

bool isFailure(Status s) {
  return s == Status::Fail || s == Status::Crash || s == Status::Timeout || s == Status::UnexpectedPass;
}

std::string deviceJson(const std::string& label, const DeviceInfo& info) {
  auto id = [](uint32_t v) { return v ? json(v) : json(nullptr); };
  auto str = [](const std::string& s) { return s.empty() ? json(nullptr) : json(s); };
  return json{{"backend", label}, {"api", info.api}, {"provider", info.provider}, {"device", info.name},
              {"type", info.type}, {"driver", info.driver}, {"driver_version", str(info.driverVersion)},
              {"vendor_id", id(info.vendorId)}, {"device_id", id(info.deviceId)}, {"uuid", str(info.uuid)},
              {"float64", info.limits.float64}, {"shader_cache", str(info.shaderCache)}}.dump();
}

namespace {

std::string describe(const Buffer& buf, const std::vector<uint32_t>& parents, size_t element) {
  const size_t unit = element / buf.perUnit, within = element % buf.perUnit;
  std::string s = buf.unit + " " + std::to_string(unit);
  if ((buf.unit == "sub-triangle" || buf.unit == "patch") && unit < parents.size())
    s += " (input triangle " + std::to_string(parents[unit]) + ")";
  return s + ", value " + std::to_string(within / 4) + " (" + "xyzw"[within % 4] + ")";
}

std::string number(double v, bool f64) {
  char b[40];
  std::snprintf(b, sizeof b, f64 ? "%.17g" : "%.9g", v);
  return b;
}

// Crash, then Timeout, then Fail, then Skip: the worst outcome of the two sides names the result.
int rank(Status s) { return s == Status::Crash ? 4 : s == Status::Timeout ? 3 : s == Status::Fail ? 2 : s == Status::Skip ? 1 : 0; }

}  // namespace

std::vector<Result> compareRuns(const std::vector<Case>& cases, const std::vector<BackendRun>& runs,
                                const std::vector<std::pair<size_t, size_t>>& pairs) {
  std::vector<Result> results;
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const Case& c = cases[ci];
    std::vector<std::optional<CaseOutput>> outputs(runs.size());
    const std::vector<std::string> names = bufferNames(c);
    for (size_t r = 0; r < runs.size(); ++r)
      if (runs[r].cases[ci].status == Status::Pass) outputs[r] = readCaseOutput(runs[r].dir / c.name);
    for (auto [ia, ib] : pairs) {
      const BackendRun &A = runs[ia], &B = runs[ib];
      for (const std::string& name : names) {
        Result r;
        r.caseName = c.name, r.buffer = name, r.a = A.label, r.b = B.label;
        r.test = c.name + "/" + name + "/" + A.label + "-vs-" + B.label;
        const CaseRun &ra = A.cases[ci], &rb = B.cases[ci];
        if (ra.status != Status::Pass || rb.status != Status::Pass) {
          const bool aWorse = rank(ra.status) >= rank(rb.status);
          r.status = aWorse ? ra.status : rb.status;
          r.message = (aWorse ? A.label : B.label) + ": " + (aWorse ? ra.detail : rb.detail);
          results.push_back(r);
          continue;
        }
        const Buffer *ba = nullptr, *bb = nullptr;
        for (const Buffer& b : outputs[ia]->buffers) if (b.name == name) ba = &b;
        for (const Buffer& b : outputs[ib]->buffers) if (b.name == name) bb = &b;
        if (!ba || !bb) {
          r.status = Status::Fail;
          r.message = (ba ? B.label : A.label) + " has no buffer " + name;
          results.push_back(r);
          continue;
        }
        r.tolerance = crossDeviceTolerance(name, c.strict(), c.f64());
        r.compare = compareBuffers(ba->values, bb->values, !c.f64(), r.tolerance);
        r.compared = true;
        r.status = r.compare.mismatched ? Status::Fail : Status::Pass;
        if (ba->values.size() != bb->values.size()) {
          r.message = name + ": " + std::to_string(ba->values.size()) + " values on " + A.label + ", " +
                      std::to_string(bb->values.size()) + " on " + B.label;
        } else if (r.compare.mismatched) {
          FirstMismatch f;
          f.element = r.compare.firstMismatch;
          f.where = describe(*ba, outputs[ia]->parents, f.element);
          f.a = ba->values[f.element], f.b = bb->values[f.element];
          f.ulp = c.f64() ? ulpDistance(f.a, f.b) : ulpDistance(float(f.a), float(f.b));
          r.message = "first mismatch " + name + "[" + std::to_string(f.element) + "]: " + f.where + ": " +
                      number(f.a, c.f64()) + " on " + A.label + " vs " + number(f.b, c.f64()) + " on " + B.label + " (" +
                      std::to_string(f.ulp) + " ulp); " + std::to_string(r.compare.mismatched) + " of " +
                      std::to_string(r.compare.total) + " values mismatched";
          r.first = f;
        }
        results.push_back(r);
      }
    }
  }
  return results;
}

void applyBaseline(std::vector<Result>& results, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorKind::Input, path + ": cannot read the baseline");
  std::map<std::string, std::string> expected;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const size_t comma = line.rfind(',');
    if (comma == std::string::npos) throw inputError(path, n, "a baseline line is TEST,STATUS");
    const std::string status = line.substr(comma + 1);
    if (status != "Fail" && status != "Crash" && status != "Timeout")
      throw inputError(path, n, "the status of an expected failure is Fail, Crash or Timeout, not '" + status + "'");
    expected[line.substr(0, comma)] = status;
  }
  for (Result& r : results) {
    auto it = expected.find(r.test);
    if (it == expected.end()) continue;
    if (r.status == Status::Pass) {
      r.status = Status::UnexpectedPass;
      r.message = "passes, but the baseline expects " + it->second;
    } else if (statusName(r.status) == it->second) {
      r.status = Status::ExpectedFail;
    }
  }
}

void printText(const std::vector<Result>& results, bool prefixCase) {
  for (const Result& r : results) {
    if (!r.compared) continue;
    const std::string name = prefixCase ? r.caseName + "/" + r.buffer : r.buffer;
    std::printf("%s %s vs %s: max_abs=%.3g max_ulp=%llu mismatched=%zu/%zu\n", name.c_str(), r.a.c_str(), r.b.c_str(),
                r.compare.maxAbs, (unsigned long long)r.compare.maxUlp, r.compare.mismatched, r.compare.total);
  }
  std::fflush(stdout);
  for (const Result& r : results)
    if (r.status == Status::Fail || r.status == Status::UnexpectedPass || r.status == Status::ExpectedFail)
      std::fprintf(stderr, "sffd: conform: %s %s: %s\n", statusName(r.status), r.test.c_str(), r.message.c_str());
}

namespace {

std::string xml(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&apos;"; break;
      default: o += (static_cast<unsigned char>(ch) < 0x20 && ch != '\t') ? ' ' : ch;
    }
  }
  return o;
}

// A report replaces a file as every output does (a temporary renamed into place: the file it replaces is
// kept aside meanwhile, WrittenFiles); a pipe, a device or the file stdout goes to is written in place
// (--json /dev/stdout works), where a write that fails is an error (into /dev/full the report was lost
// without a word, exit 0).
void writeReport(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (!writtenInPlace(replacedFile(path))) return writeFileAtomically(path, write);
  std::ofstream f(path);
  if (!f) throw Error(ErrorKind::Input, path + ": cannot write");
  write(f);
  f.flush();
  if (!f) throw Error(ErrorKind::Input, path + ": cannot write: write failed (disk full?)");
}

json numberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

}  // namespace

void writeJunit(const std::string& path, const std::vector<Result>& results) {
  // One testsuite per case; Fail and UnexpectedPass are failures, Crash and Timeout errors.
  std::vector<std::string> order;
  std::map<std::string, std::vector<const Result*>> byCase;
  for (const Result& r : results) {
    if (!byCase.count(r.caseName)) order.push_back(r.caseName);
    byCase[r.caseName].push_back(&r);
  }
  auto count = [](const std::vector<const Result*>& rs, auto pred) {
    size_t n = 0;
    for (const Result* r : rs) n += pred(r->status);
    return n;
  };
  auto failure = [](Status s) { return s == Status::Fail || s == Status::UnexpectedPass; };
  auto error = [](Status s) { return s == Status::Crash || s == Status::Timeout; };
  auto skipped = [](Status s) { return s == Status::Skip; };
  writeReport(path, [&](std::ostream& f) {
    f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"sffd conform\" tests=\"" << results.size() << "\">\n";
    for (const std::string& c : order) {
      const auto& rs = byCase[c];
      f << " <testsuite name=\"" << xml(c) << "\" tests=\"" << rs.size() << "\" failures=\"" << count(rs, failure)
        << "\" errors=\"" << count(rs, error) << "\" skipped=\"" << count(rs, skipped) << "\">\n";
      for (const Result* r : rs) {
        f << "  <testcase classname=\"sffd.conform." << xml(c) << "\" name=\"" << xml(r->buffer + "/" + r->a + "-vs-" + r->b)
          << "\"";
        const std::string m = xml(r->message);
        if (failure(r->status))
          f << ">\n   <failure type=\"" << statusName(r->status) << "\" message=\"" << m << "\">" << m << "</failure>\n  </testcase>\n";
        else if (error(r->status))
          f << ">\n   <error type=\"" << statusName(r->status) << "\" message=\"" << m << "\">" << m << "</error>\n  </testcase>\n";
        else if (skipped(r->status))
          f << ">\n   <skipped message=\"" << m << "\"/>\n  </testcase>\n";
        else if (r->status == Status::ExpectedFail)
          f << ">\n   <system-out>ExpectedFail: " << m << "</system-out>\n  </testcase>\n";
        else
          f << "/>\n";
      }
      f << " </testsuite>\n";
    }
    f << "</testsuites>\n";
  });
}

void writeJson(const std::string& path, const std::vector<Case>& cases, const std::vector<BackendRun>& runs,
               const std::vector<Result>& results) {
  json j;
  j["format"] = "sffd-conform-results";
  j["version"] = 1;
  bool fail = false;
  for (const Result& r : results) fail = fail || isFailure(r.status);
  j["status"] = fail ? "FAIL" : "PASS";
  j["backends"] = json::array();
  for (const BackendRun& b : runs) {
    json d = b.opened ? json::parse(deviceJson(b.label, b.info)) : json{{"backend", b.label}};
    d["status"] = b.opened ? "ok" : "skip";
    if (!b.opened) d["reason"] = b.skipReason.empty() ? b.cases.empty() ? "" : b.cases[0].detail : b.skipReason;
    j["backends"].push_back(d);
  }
  j["cases"] = json::array();
  for (const Case& c : cases) {
    json args = json::array();
    for (size_t i = 1; i < c.argv.size(); ++i) args.push_back(c.argv[i]);
    j["cases"].push_back({{"name", c.name}, {"mesh", c.argv[0]}, {"lattice", c.args.get("--lattice")},
                          {"method", c.method()}, {"variant", c.variant()}, {"arguments", args},
                          {"input_hashes", inputHashes(c)}});
  }
  j["results"] = json::array();
  for (const Result& r : results) {
    json o{{"test", r.test}, {"case", r.caseName}, {"buffer", r.buffer}, {"pair", {r.a, r.b}}, {"status", statusName(r.status)}};
    if (r.compared) {
      o["max_abs"] = numberOrNull(r.compare.maxAbs);
      o["max_ulp"] = r.compare.maxUlp;
      o["mismatched"] = r.compare.mismatched;
      o["total"] = r.compare.total;
      o["tolerance"] = {{"bit_exact", r.tolerance.bitExact}, {"max_ulp", r.tolerance.maxUlp},
                        {"abs_of_scale", r.tolerance.absOfScale}};
    }
    o["first_mismatch"] = r.first ? json{{"element", r.first->element}, {"where", r.first->where},
                                         {"a", numberOrNull(r.first->a)}, {"b", numberOrNull(r.first->b)}, {"ulp", r.first->ulp}}
                                  : json(nullptr);
    if (!r.message.empty()) o["message"] = r.message;
    j["results"].push_back(o);
  }
  writeReport(path, [&](std::ostream& f) { f << j.dump(1) << "\n"; });
}

}  // namespace sffd::cli::conform
