// GPU contexts held until the process exits. Mesa's drivers (OSMesa, lavapipe) and the Vulkan
// layers register exit handlers when they are loaded, and those tear down state the drivers
// need: a context destroyed after them (by a static object's destructor) can crash. So once a
// driver is loaded, the backend calls driver_loaded(), whose own exit handler, registered after
// the driver's, runs before it and marks the exit; a backend destroyed after that leaves its
// context to the operating system.
#pragma once

#include <memory>

namespace flatmarch {

// Call after loading a driver (making a context).
void driver_loaded();
// Whether the process is exiting (after main).
bool process_exiting();
// Keeps an object reachable and never destroys it (a leak checker does not report it).
void leave_to_the_os(std::shared_ptr<void> object);

// Destroys `context`, or, when the process is exiting, leaves it to the operating system.
template <typename T>
void release_context(std::unique_ptr<T>& context) {
  if (process_exiting() && context) leave_to_the_os(std::shared_ptr<T>(std::move(context)));
}

}  // namespace flatmarch
