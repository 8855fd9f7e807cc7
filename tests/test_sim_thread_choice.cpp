// The run's thread count when left to choose (src/sim/thread_choice.hpp): every core while they pay, one where they
// do not, found again when the machine changes; probes that lose come less and less often.
#include "../src/sim/thread_choice.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <vector>

using tethash::sim::detail::ThreadChoice;

namespace {

/// The counts of `steps` steps whose time per substep at `threads` on step i is cost(i, threads).
std::vector<int> run(ThreadChoice& choice, int steps, const std::function<double(int, int)>& cost)
{
    std::vector<int> counts;
    for (int i = 0; i < steps; ++i) {
        counts.push_back(choice.threads());
        choice.record(cost(i, choice.threads()));
    }
    return counts;
}

int steps_at(const std::vector<int>& counts, int threads, size_t from = 0)
{
    int n = 0;
    for (size_t i = from; i < counts.size(); ++i)
        n += counts[i] == threads ? 1 : 0;
    return n;
}

} // namespace

TEST(SimThreadChoice, OneCoreHasNothingToChoose)
{
    ThreadChoice choice(1);
    const std::vector<int> counts = run(choice, 200, [](int, int t) { return t == 1 ? 5.0 : 1.0; });
    EXPECT_EQ(steps_at(counts, 1), 200);
    EXPECT_EQ(choice.switches(), 0);
}

TEST(SimThreadChoice, MovesToEveryCoreWhereTheyPayAndProbesLessAndLessOften)
{
    // Two threads take 0.7 of one thread's time: the run starts on one, moves to both at its first probe and stays
    // there; its probes on one thread (probe_steps each) double their interval after each loss, so 1,000 steps hold
    // at most six of them.
    ThreadChoice choice(2);
    const std::vector<int> counts = run(choice, 1000, [](int, int t) { return t == 2 ? 0.7 : 1.0; });
    EXPECT_EQ(counts.front(), 1);
    EXPECT_EQ(counts[ThreadChoice::first_probe], 2); // the first probe comes early
    EXPECT_EQ(counts.back(), 2);
    EXPECT_EQ(choice.switches(), 1);
    const size_t settled = ThreadChoice::first_probe + ThreadChoice::probe_steps;
    const int probes = steps_at(counts, 1, settled) / ThreadChoice::probe_steps;
    EXPECT_GE(probes, 3);
    EXPECT_LE(probes, 6);
    EXPECT_EQ(steps_at(counts, 1, settled) % ThreadChoice::probe_steps, 0);
}

TEST(SimThreadChoice, StaysOnOneThreadWhereMoreDoNotPay)
{
    // A loaded machine: two threads take six times as long. The run stays on one thread but for rare probes of
    // two, eight times further apart after each (they lose by more than twice) up to max_interval: four in 1,000
    // steps (at 4, 38, 296 and 810).
    ThreadChoice choice(2);
    const std::vector<int> counts = run(choice, 1000, [](int, int t) { return t == 2 ? 6.0 : 1.0; });
    EXPECT_EQ(choice.switches(), 0);
    EXPECT_EQ(counts.back(), 1);
    EXPECT_EQ(steps_at(counts, 2), 4 * ThreadChoice::probe_steps);
}

TEST(SimThreadChoice, FindsTheOtherCountAgainWhenTheMachineChanges)
{
    // Idle for 600 steps (two threads pay), then loaded (they take five times as long), then idle again from 1,800:
    // each change is followed within two of the longest probe intervals.
    auto loaded = [](int i) { return i >= 600 && i < 1800; };
    ThreadChoice choice(2);
    const std::vector<int> counts =
        run(choice, 3000, [&](int i, int t) { return t == 2 ? (loaded(i) ? 5.0 : 0.6) : 1.0; });
    const size_t lag = 2 * ThreadChoice::max_interval;
    EXPECT_EQ(counts[599], 2);
    EXPECT_EQ(counts[600 + lag], 1);
    EXPECT_EQ(counts[1799], 1);
    EXPECT_EQ(counts[1800 + lag], 2);
    EXPECT_EQ(counts.back(), 2);
    EXPECT_EQ(choice.switches(), 3);
}

TEST(SimThreadChoice, AProbeIsJudgedWithoutItsFirstStep)
{
    // The first step after a change of count costs more (the detector's candidate lists rebuilt): 20 here, while
    // one thread is steadily 1.0 and two 0.5. The probe must not be judged by that step: the run moves to two and
    // stays there.
    ThreadChoice choice(2);
    int last = 1;
    std::vector<int> counts;
    for (int i = 0; i < 400; ++i) {
        const int t = choice.threads();
        const bool changed = t != last;
        last = t;
        counts.push_back(t);
        choice.record(changed ? 20.0 : (t == 2 ? 0.5 : 1.0));
    }
    EXPECT_EQ(choice.switches(), 1);
    EXPECT_EQ(counts.back(), 2);
}
