// Private data layout of the reference DEM world: neighbour lists as compressed rows,
// the pool of contact histories (touching contacts only) and its carry-over across a
// list rebuild.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "contact_law.hpp"

namespace pdamp::dem_reference::detail {

/// `Slot::contact` of a listed pair that overlaps at the rebuild but has no history to
/// carry over (first list, or a particle set by hand): it gets a fresh pool entry.
inline constexpr int kFreshContact = -2;

/// One entry of a neighbour row (12 bytes): the row's particle i, its partner j (a
/// particle j > i, or a wall index) and their contact in the pool, if any. The
/// contact's parameters live in the pool: most listed pairs never touch, and a slot
/// this small keeps the lists a minor part of the memory. (i is implied by the row; it
/// is stored so that loops can run over the slots of many rows at once.)
struct Slot {
  int i = 0;
  int j = 0;
  int contact = -1;  ///< index in the row list's pool; -1 = none
};

/// What the force loop reads and writes for a touching contact (80 bytes).
struct Contact {
  ContactParams params;
  ContactHistory history;
};

/// The pair a pooled contact belongs to: particle i, and particle j > i or wall j.
struct ContactKey {
  int i = 0;
  int j = 0;
};

/// Histories of the contacts of one row list as parallel arrays: the force loop
/// streams `state` and touches `rolling` only for pair types with rolling resistance;
/// the keys are read when the lists are rebuilt. A slot whose contact ends keeps its
/// entry (reset), so that the pool never holds more entries than slots.
struct ContactPool {
  std::vector<Contact> state;
  std::vector<ContactKey> keys;
  std::vector<std::array<double, 3>> rolling;  ///< M_r on i, N·m; empty without rolling resistance
  bool with_rolling = false;

  std::size_t size() const { return state.size(); }
  double* rolling_torque(std::size_t e) { return with_rolling ? rolling[e].data() : nullptr; }
  const double* rolling_torque(std::size_t e) const { return with_rolling ? rolling[e].data() : nullptr; }
  /// Capacity for `count` entries; when outgrown, 1/8 more than needed rather than the
  /// standard library's doubling (the pool is a large part of the memory).
  void reserve(std::size_t count) {
    if (count <= state.capacity()) return;
    const std::size_t grown = count + count / 8;
    state.reserve(grown);
    keys.reserve(grown);
    if (with_rolling) rolling.reserve(grown);
  }
  /// Appends a contact; returns its index.
  int add(const ContactKey& key, const Contact& contact, const double* torque) {
    reserve(state.size() + 1);
    state.push_back(contact);
    keys.push_back(key);
    if (with_rolling) rolling.push_back({torque[0], torque[1], torque[2]});
    return static_cast<int>(state.size()) - 1;
  }
  /// The contact of entry e has ended: fresh history for a later touch of the same slot.
  void reset(std::size_t e) {
    state[e].history = ContactHistory{};
    if (with_rolling) rolling[e] = {0.0, 0.0, 0.0};
  }
  void swap_entries(std::size_t a, std::size_t b) {
    std::swap(state[a], state[b]);
    std::swap(keys[a], keys[b]);
    if (with_rolling) std::swap(rolling[a], rolling[b]);
  }
  void resize(std::size_t count) {
    state.resize(count);
    keys.resize(count);
    if (with_rolling) rolling.resize(count);
  }
  /// Drops the entries of contacts not in touch (before a rebuild; order kept).
  void drop_ended() {
    std::size_t kept = 0;
    for (std::size_t e = 0; e < state.size(); ++e) {
      if (state[e].history.gamma < 0.0) continue;
      if (kept != e) {
        state[kept] = state[e];
        keys[kept] = keys[e];
        if (with_rolling) rolling[kept] = rolling[e];
      }
      ++kept;
    }
    resize(kept);
  }
  std::size_t memory_bytes() const {
    return state.capacity() * sizeof(Contact) + keys.capacity() * sizeof(ContactKey) +
           rolling.capacity() * sizeof(rolling[0]);
  }
};

/// Neighbour lists of all particles as compressed rows: the partners of particle i are
/// slots[offsets[i] .. offsets[i+1]), ascending.
struct RowList {
  std::vector<int> offsets;
  std::vector<Slot> slots;
  ContactPool pool;
  std::vector<int> target;  ///< scratch of a rebuild: new place of each pool entry

  std::size_t memory_bytes() const {
    return offsets.capacity() * sizeof(int) + slots.capacity() * sizeof(Slot) + pool.memory_bytes() +
           target.capacity() * sizeof(int);
  }
};

/// After the rows were rebuilt (slots with contact −1, or kFreshContact where a pair
/// overlaps): links every pooled contact to its slot, gives fresh entries with the
/// parameters `params(i, j)` to the kFreshContact slots, and reorders the pool into
/// slot order, so that the force loop reads it sequentially. A touching pair is always
/// listed (its gap is below the skin); an entry that finds no slot is dropped. The
/// reordering is an in-place permutation: no second pool is kept.
template <class Params>
void attach_contacts(RowList& list, Params&& params) {
  auto& pool = list.pool;
  const std::size_t carried = pool.size();
  for (std::size_t e = 0; e < carried; ++e) {
    const auto i = static_cast<std::size_t>(pool.keys[e].i);
    for (int s = list.offsets[i]; s < list.offsets[i + 1]; ++s) {
      Slot& slot = list.slots[static_cast<std::size_t>(s)];
      if (slot.j == pool.keys[e].j) {
        slot.contact = static_cast<int>(e);
        break;
      }
    }
  }
  // New places in slot order; fresh entries are appended first, then moved with the rest.
  list.target.assign(carried, -1);
  int place = 0;
  const int rows = static_cast<int>(list.offsets.size()) - 1;
  const double no_torque[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < rows; ++i) {
    for (int s = list.offsets[static_cast<std::size_t>(i)]; s < list.offsets[static_cast<std::size_t>(i) + 1]; ++s) {
      Slot& slot = list.slots[static_cast<std::size_t>(s)];
      if (slot.contact == kFreshContact) {
        Contact fresh;
        fresh.params = params(i, slot.j);
        slot.contact = pool.add(ContactKey{i, slot.j}, fresh, no_torque);
        list.target.push_back(-1);
      }
      if (slot.contact >= 0) {
        list.target[static_cast<std::size_t>(slot.contact)] = place;
        slot.contact = place++;
      }
    }
  }
  // Entries without a slot go behind the kept ones and are cut off.
  int tail = place;
  for (auto& t : list.target) {
    if (t < 0) t = tail++;
  }
  for (std::size_t e = 0; e < pool.size(); ++e) {
    while (list.target[e] != static_cast<int>(e)) {
      const auto to = static_cast<std::size_t>(list.target[e]);
      pool.swap_entries(e, to);
      std::swap(list.target[e], list.target[to]);
    }
  }
  pool.resize(static_cast<std::size_t>(place));
}

}  // namespace pdamp::dem_reference::detail
