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
    /// A thread's working buffers (grown only). A run of a tet's pairs that passed the object rules (`run`) goes
    /// through the hash's face-plane filter (`values`, `codes`, `kept`: scan.hpp); the pairs it leaves (inside or
    /// undecided) go to the oracle's inside test a block at a time (`vertex` ... `bary`: inside_batch.hpp).
    struct Work {
        std::vector<Index> run;
        std::vector<double> values;
        std::vector<std::int8_t> codes;
        std::vector<std::int32_t> kept;
        std::vector<Index> vertex, tet;
        std::vector<std::uint8_t> inside;
        std::vector<double> bary;
        std::int64_t bytes() const;
    };
    Method m_method = Method::hash;
    std::unique_ptr<BroadPhase> m_broad;
    std::vector<CandidateSink> m_sinks;
    std::vector<std::vector<Found>> m_found;
    std::vector<Work> m_work;
    std::vector<Counts> m_counts;
    std::vector<Found> m_all;
};

} // namespace tethash::detail
