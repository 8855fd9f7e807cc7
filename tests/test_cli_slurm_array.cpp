// docs/slurm_study_array.sh, the job-array script of docs/embedding.md, run as Slurm would run it: one process per
// array task with SLURM_ARRAY_TASK_ID/COUNT/MIN set, then the merge job. The merged study must equal the
// unsharded one (timing columns aside).
#include "study_support.hpp"
#include "support.hpp"

#include "tethash/study/table.hpp"

namespace tethash {
namespace {

using study::Table;

TEST(CliSlurmArray, ArrayTasksThenMergeEqualTheUnshardedStudy)
{
    const auto dir = test::temp_dir();
    const std::string mesh = test::quote(test::two_boxes(dir, 2, Eigen::RowVector3d(0.31, 0.17, 0.23)));
    const std::string args = "cell-size --mesh " + mesh + " --cell-size x0.5,x0.7,x1,x1.4,x2 --repeat 1 --warmup 0";
    const std::string script = test::quote(std::filesystem::path(TETHASH_SOURCE_DIR) / "docs" / "slurm_study_array.sh");
    const std::string env = "TETHASH=" + test::quote(TETHASH_EXE) + " STUDY_OUT=" + test::quote(dir / "array") +
                            " STUDY_ARGS='" + args + "' ";
    // An array 1-3 (not starting at 0): task ids 1, 2, 3 are shards 0, 1, 2.
    for (int id = 1; id <= 3; ++id) {
        const auto r = test::run_shell(env + "SLURM_ARRAY_TASK_ID=" + std::to_string(id) +
                                       " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=3 bash " + script);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_TRUE(std::filesystem::exists(dir / "array" / ("shard_" + std::to_string(id - 1)) / "study.csv"));
    }
    const auto merge = test::run_shell(env + "bash " + script + " merge");
    ASSERT_EQ(merge.status, 0) << merge.err;
    EXPECT_EQ(merge.out.find("missing"), std::string::npos) << merge.out;

    const auto whole = test::run_tethash("study " + args + " --no-plot --quiet --out " + test::quote(dir / "whole"));
    ASSERT_EQ(whole.status, 0) << whole.err;
    const Table all = Table::read_csv((dir / "whole" / "study.csv").string());
    const Table merged = Table::read_csv((dir / "array" / "merged" / "study.csv").string());
    EXPECT_EQ(all.rows.size(), 5u);
    EXPECT_EQ(test::deterministic(all).rows, test::deterministic(merged).rows);

    // Outside a job array the script says how to submit it.
    const auto bare = test::run_shell(env + "bash " + script);
    EXPECT_NE(bare.status, 0);
    EXPECT_NE(bare.err.find("sbatch --array"), std::string::npos) << bare.err;
}

} // namespace
} // namespace tethash
