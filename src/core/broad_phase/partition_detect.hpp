#pragma once
// The detector's path for the methods other than the hash (private header): a broad phase (broad_phase.hpp) finds
// the candidates, the exact stage shared by every method tests them and sorts the contacts.
#include "../hash/detect_checks.hpp"
#include "broad_phase.hpp"

#include <memory>
#include <vector>

namespace tethash::detail {

class PartitionDetector {
  public:
    /// Drops the structure (a new topology or new parameters): the next call builds from scratch.
    void reset();
    /// Runs `method`'s broad phase and the exact stage on `scene`; fills `contacts` sorted by (vertex, tet), the
    /// same for every method and thread count. `stats` (optional) gets the stage times and counters.
    void detect(Method method, const PartitionScene& scene, const Index* vertex_object, const Index* tet_object,
                const ObjectFlags& flags, std::vector<Contact>& contacts, DetectStats* stats);
    std::int64_t memory_bytes() const;

  private:
    /// A contact before the sort: (vertex, tet) and the barycentric coordinates.
    struct Found {
        Index vertex, tet;
        double bary[4];
    };
    struct alignas(64) Counts {
        std::int64_t inside_tests = 0, exact = 0, degenerate = 0;
    };
    /// A thread's pairs that passed the object rules, tested a block at a time (inside_batch.hpp).
    struct Batch {
        std::vector<Index> vertex, tet;
        std::vector<std::uint8_t> inside;
        std::vector<double> bary;
    };
    Method m_method = Method::hash;
    std::unique_ptr<BroadPhase> m_broad;
    std::vector<CandidateSink> m_sinks;
    std::vector<std::vector<Found>> m_found;
    std::vector<Batch> m_batches;
    std::vector<Counts> m_counts;
    std::vector<Found> m_all;
};

} // namespace tethash::detail
