// docs/operations.md lists every operation of the table (ops.def), in its
// order, with its operand count, domain and ULP bounds; the meaning column
// is the doc's own.  On a mismatch the test prints how the rows should
// begin, ready to paste.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include <sh/ir/op.hpp>

namespace {

std::string row_start(sh::ir::Op op) {
  const sh::ir::OpInfo& info = sh::ir::op_info(op);
  return "| `" + std::string(info.name) + "` | " + std::to_string(info.arity) + " | " +
         sh::ir::domain_name(info.domain) + " | " + std::to_string(info.ulp_precise) + " | " +
         std::to_string(info.ulp_fast) + " |";
}

TEST(OperationsDoc, ListsEveryOperationOfTheTableInItsOrder) {
  const std::string path = std::string(SH_DOCS_DIR) + "/operations.md";
  std::ifstream doc(path);
  ASSERT_TRUE(doc) << "cannot read " << path;
  std::vector<std::string> rows;
  for (std::string line; std::getline(doc, line);)
    if (line.rfind("| `", 0) == 0) rows.push_back(line);

  std::string expected;
  bool same = rows.size() == static_cast<std::size_t>(sh::ir::kOpCount);
  for (int i = 0; i < sh::ir::kOpCount; ++i) {
    std::string start = row_start(sh::ir::op_at(i));
    expected += start + " ... |\n";
    if (i >= static_cast<int>(rows.size()) || rows[i].rfind(start, 0) != 0) same = false;
  }
  EXPECT_TRUE(same) << path << " does not list the operations of dsl/include/sh/ir/ops.def (" << rows.size()
                    << " rows for " << sh::ir::kOpCount << " operations); its rows should begin:\n"
                    << expected;
}

}  // namespace
