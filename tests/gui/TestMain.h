#pragma once
// Several Qt Test classes in one executable: each test file registers its class, and the main()
// in TestMain.cpp runs them all (settings, autosaves and caches go to a temporary folder, never
// the user's).

#include <QObject>

#include <functional>
#include <memory>
#include <vector>

namespace tp::gui::test {

using Factory = std::function<std::unique_ptr<QObject>()>;
std::vector<Factory>& registry();

struct Register {
  explicit Register(Factory f) { registry().push_back(std::move(f)); }
};

}  // namespace tp::gui::test

#define TP_GUI_TEST(Class) \
  static const tp::gui::test::Register register##Class([] { return std::make_unique<Class>(); });
