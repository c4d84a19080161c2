// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDBenchmarkUtilities.h
 * @brief What every benchmark program shares (Testing/Benchmarks): the clock, the best and median of repeated
 * runs, the process's resident memory and the command line. No VTK: BenchmarkFFDCuda runs where there is none.
 */
#ifndef FFDBenchmarkUtilities_h
#define FFDBenchmarkUtilities_h

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string>
#include <utility>
#include <vector>

using Clock = std::chrono::steady_clock;

/// The seconds from `since` to `until` (now by default).
inline double Seconds(Clock::time_point since, Clock::time_point until = Clock::now())
{
  return std::chrono::duration<double>(until - since).count();
}

/// The fastest, the median (the upper one of an even count) and the slowest of some times.
struct Timing
{
  double Best = 0.0, Median = 0.0, Worst = 0.0;
};

/// The Timing of `times` (not empty).
inline Timing Summarize(std::vector<double> times)
{
  std::sort(times.begin(), times.end());
  return { times.front(), times[times.size() / 2], times.back() };
}

/// The median of `values` (not empty; the upper one of an even count).
inline double Median(std::vector<double> values)
{
  return Summarize(std::move(values)).Median;
}

/// Runs `step` (which returns the seconds of its timed part) at least `minRepeats` times and until
/// `minSeconds` have been spent; appends the timed parts to `times`.
template <typename Step>
void RepeatInto(Step&& step, int minRepeats, double minSeconds, std::vector<double>& times)
{
  const Clock::time_point begin = Clock::now();
  for (int repeats = 0; repeats < minRepeats || Seconds(begin) < minSeconds; ++repeats)
  {
    times.push_back(step());
  }
}

/// RepeatInto(); the Timing of the timed parts.
template <typename Step>
Timing Repeat(Step&& step, int minRepeats, double minSeconds = 0.0)
{
  std::vector<double> times;
  RepeatInto(step, minRepeats, minSeconds, times);
  return Summarize(std::move(times));
}

/// The median time of `runs` runs of `work` in seconds, fewer when one takes more than `enough` seconds.
template <typename Work>
double MedianSeconds(int runs, Work&& work, double enough = std::numeric_limits<double>::infinity())
{
  std::vector<double> times;
  for (int run = 0; run < runs && (times.empty() || times.back() <= enough); ++run)
  {
    const Clock::time_point start = Clock::now();
    work();
    times.push_back(Seconds(start));
  }
  return Median(std::move(times));
}

/// The process's resident memory now ("VmRSS") or at its peak since the last ResetPeakResidentMemory()
/// ("VmHWM"), in MB, from Linux's /proc/self/status; -1 where it cannot be read.
inline double ResidentMegabytes(const char* field)
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.compare(0, std::strlen(field), field) == 0)
    {
      return std::atof(line.c_str() + std::strlen(field) + 1) / 1024.0; // in kB
    }
  }
  return -1.0;
}

/// Starts a new peak at the current resident memory (Linux: clear_refs 5), so that a later peak is not that of
/// what came before (reading and subdividing a mesh).
inline void ResetPeakResidentMemory()
{
  std::ofstream("/proc/self/clear_refs") << "5";
}

/// One option of a benchmark's command line: a flag ("--quick"), or a name and its value ("--mesh path"): a text,
/// one of a list of choices ("global|bases|all"), or a whole number.
struct BenchmarkOption
{
  BenchmarkOption(const char* name, bool* flag)
    : Name(name)
    , Flag(flag)
  {
  }
  BenchmarkOption(const char* name, std::string* text, const char* choices = nullptr)
    : Name(name)
    , Text(text)
    , Choices(choices)
  {
  }
  BenchmarkOption(const char* name, int* number)
    : Name(name)
    , Number(number)
  {
  }

  /// Sets the option's value from `text`; false where the option does not take it.
  bool SetValue(const char* text) const
  {
    if (this->Number)
    {
      char* end = nullptr;
      *this->Number = static_cast<int>(std::strtol(text, &end, 10));
      return end != text && *end == '\0';
    }
    *this->Text = text;
    return !this->Choices ||
      (std::string("|") + this->Choices + "|").find(std::string("|") + text + "|") != std::string::npos;
  }

  const char* Name;
  bool* Flag = nullptr;
  std::string* Text = nullptr;
  const char* Choices = nullptr; // '|'-separated; any text where null
  int* Number = nullptr;
};

/**
 * Reads the command line into `options`. Where it holds anything else, an option without its value or with a
 * value it does not take, or --help (-h), it prints "usage: <program> <usage>" (on stdout for --help, else on
 * stderr), sets `status` to the exit status (0 for --help, else 2) and returns false.
 */
inline bool ParseArguments(
  int argc, char* argv[], std::initializer_list<BenchmarkOption> options, const char* usage, int& status)
{
  for (int a = 1; a < argc; ++a)
  {
    const char* argument = argv[a];
    const auto option = std::find_if(options.begin(), options.end(),
      [argument](const BenchmarkOption& candidate) { return std::strcmp(argument, candidate.Name) == 0; });
    bool ok = option != options.end();
    if (ok && option->Flag)
    {
      *option->Flag = true;
    }
    else if (ok)
    {
      ok = a + 1 < argc && option->SetValue(argv[++a]);
    }
    if (!ok)
    {
      const bool help = !std::strcmp(argument, "--help") || !std::strcmp(argument, "-h");
      std::fprintf(help ? stdout : stderr, "usage: %s %s\n", argv[0], usage);
      status = help ? 0 : 2;
      return false;
    }
  }
  return true;
}

#endif
