// Private data layout of the reference DEM world: Verlet-list slots and the carry-over
// of contact history across a list rebuild.
#pragma once

#include <vector>

#include "contact_law.hpp"

namespace pdamp::dem_reference::detail {

/// One entry of a Verlet list: particle i and either particle j (> i) or wall j.
struct Slot {
  int i = 0;
  int j = 0;
  ContactParams params;
};

/// A contact in touch, saved across a rebuild.
struct ActiveContact {
  int i = 0;
  int j = 0;
  ContactHistory history;
};

/// Saves the contacts in touch (γ_n set) before a rebuild, in (i, j) order. Only
/// touching contacts are copied so that the spare memory is per contact, not per slot.
inline void save_active(const std::vector<Slot>& slots, const std::vector<ContactHistory>& history,
                        std::vector<ActiveContact>& active) {
  active.clear();
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (history[k].gamma >= 0.0) active.push_back(ActiveContact{slots[k].i, slots[k].j, history[k]});
  }
}

/// Gives the rebuilt list fresh history and puts the saved contacts back. Both lists
/// are sorted by (i, j), so one merge pass suffices; a touching pair is always in the
/// new list (its gap is below the skin).
inline void restore_active(const std::vector<Slot>& slots, std::vector<ContactHistory>& history,
                           const std::vector<ActiveContact>& active) {
  history.assign(slots.size(), ContactHistory{});
  std::size_t k = 0;
  for (const auto& a : active) {
    while (k < slots.size() && (slots[k].i < a.i || (slots[k].i == a.i && slots[k].j < a.j))) ++k;
    if (k < slots.size() && slots[k].i == a.i && slots[k].j == a.j) history[k] = a.history;
  }
}

}  // namespace pdamp::dem_reference::detail
