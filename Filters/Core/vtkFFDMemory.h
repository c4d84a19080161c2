// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDMemory.h
 * @brief Sizes from user input checked before they are allocated (private to the Filters module).
 *
 * A size that a user sets (divisions, subdivision levels) can ask for more memory than the machine has. Linux
 * lets a process reserve far more than it can touch, so a request is compared with the memory the system says
 * it can still give (MemAvailable) before anything is allocated, and refused with an error that says what was
 * asked and what it needs. Sizes are counted in double, which neither overflows nor wraps where an integer
 * product of three sizes would.
 */
#ifndef vtkFFDMemory_h
#define vtkFFDMemory_h

#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkInformationVector.h"
#include "vtkSetGet.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>

/**
 * The bytes this process can still be given: the lesser of the system's MemAvailable (/proc/meminfo; else the
 * physical memory) and the room left under its control group's memory.max (a container's limit, past which
 * the kernel kills the process rather than failing an allocation). An address-space limit (RLIMIT_AS) makes
 * allocations fail instead, which the filters catch (vtkFFDCatchAllocationFailure()).
 */
inline double vtkFFDAvailableMemory()
{
  auto readNumber = [](const char* path, const char* format, double& value)
  {
    FILE* file = std::fopen(path, "r");
    if (!file)
    {
      return false;
    }
    char line[256];
    bool found = false;
    while (!found && std::fgets(line, sizeof(line), file))
    {
      found = std::sscanf(line, format, &value) == 1;
    }
    std::fclose(file);
    return found;
  };
  double available = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  double value;
  if (readNumber("/proc/meminfo", "MemAvailable: %lf kB", value))
  {
    available = value * 1024.0;
  }
  double used;
  if (readNumber("/sys/fs/cgroup/memory.max", "%lf", value) &&
    readNumber("/sys/fs/cgroup/memory.current", "%lf", used)) // "max" (no limit) reads as no number
  {
    available = std::min(available, std::max(0.0, value - used));
  }
  return available;
}

/// "12.3 GB" and the like.
inline std::string vtkFFDFormatBytes(double bytes)
{
  const char* units[] = { "bytes", "KB", "MB", "GB", "TB", "PB", "EB" };
  int u = 0;
  while (bytes >= 1024.0 && u < 6)
  {
    bytes /= 1024.0;
    ++u;
  }
  std::ostringstream text;
  text << std::setprecision(3) << bytes << " " << units[u];
  return text.str();
}

/**
 * True where `bytes` can be had; otherwise reports on `self` that `request` (what the user asked for, in its
 * words) needs that much, and how much the system has, and returns false.
 */
inline bool vtkFFDCheckMemory(vtkAlgorithm* self, const std::string& request, double bytes)
{
  const double available = vtkFFDAvailableMemory();
  if (bytes <= available)
  {
    return true;
  }
  vtkErrorWithObjectMacro(self, << request << " needs " << vtkFFDFormatBytes(bytes) << " of memory, but only "
                                << vtkFFDFormatBytes(available) << " is available.");
  return false;
}

/**
 * Runs `request()` (a filter's Superclass::ProcessRequest) and turns an allocation that failed anyway, one that
 * VTK, OpenVDB or the standard library could not make (std::bad_alloc, std::length_error), into an error and
 * empty outputs rather than an exception that ends the process: the filters' ProcessRequest() overrides.
 */
template <typename Request>
vtkTypeBool vtkFFDCatchAllocationFailure(vtkAlgorithm* self, vtkInformationVector* outputs, Request&& request)
{
  std::string what;
  try
  {
    return request();
  }
  catch (const std::bad_alloc&)
  {
    what = "an allocation failed";
  }
  catch (const std::length_error& e)
  {
    what = std::string("a size was too large (") + e.what() + ")";
  }
  for (int i = 0; outputs && i < outputs->GetNumberOfInformationObjects(); ++i)
  {
    if (vtkDataObject* output = vtkDataObject::GetData(outputs, i))
    {
      output->Initialize();
    }
  }
  vtkErrorWithObjectMacro(self, << "Out of memory: " << what << "; the output is empty.");
  return 0;
}

#endif
