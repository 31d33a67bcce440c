#include "romo/drivers/frame_source.hpp"

#include <map>
#include <mutex>

#include "romo/core/check.hpp"

namespace romo::drivers {
namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, SourceFactory> factories;
};

Registry& GetRegistry() {
  static Registry registry;
  return registry;
}

}  // namespace

// Built-in schemes live in their own translation units; each defines one of these.
void RegisterBuiltinSchemes(std::map<std::string, SourceFactory>* factories);

void RegisterSourceScheme(const std::string& scheme, SourceFactory factory) {
  ROMO_THROW_UNLESS(!scheme.empty() && factory);
  auto& registry = GetRegistry();
  std::lock_guard<std::mutex> lock(registry.mutex);
  registry.factories[scheme] = std::move(factory);
}

std::unique_ptr<FrameSource> OpenSource(const std::string& text) {
  const Uri uri = Uri::Parse(text);
  SourceFactory factory;
  std::string known;
  {
    auto& registry = GetRegistry();
    std::lock_guard<std::mutex> lock(registry.mutex);
    RegisterBuiltinSchemes(&registry.factories);
    const auto it = registry.factories.find(uri.scheme);
    if (it != registry.factories.end()) factory = it->second;
    for (const auto& [scheme, unused] : registry.factories) {
      known += (known.empty() ? "" : ", ") + scheme + "://";
    }
  }
  if (!factory) {
    Fail("unknown source URI scheme '" + uri.scheme + "' in '" + text + "' (known: " + known + ")");
  }
  return factory(uri);
}

}  // namespace romo::drivers
