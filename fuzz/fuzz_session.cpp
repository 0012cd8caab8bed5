// libFuzzer target: the application's session reader (JSON: tissue path, parameters, schedule,
// sites, curves) on arbitrary bytes, as File ▸ Open session reads them (loadSession calls
// sessionFromText). A refusal must be a std::runtime_error naming the key; anything else, a
// crash, a leak or undefined behaviour is a finding. An accepted session must survive a round
// trip through its JSON unchanged.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "SessionFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tp::gui::SessionState s = tp::gui::sessionFromText(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.tpsession");
    // Written back, an accepted session must read again to the same JSON.
    const nlohmann::json again = tp::gui::sessionToJson(s);
    const tp::gui::SessionState s2 = tp::gui::sessionFromJson(again, "fuzz.tpsession");
    if (tp::gui::sessionToJson(s2) != again) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
