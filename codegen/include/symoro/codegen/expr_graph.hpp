// The compiler's expression IR: a hash-consed DAG. Structurally equal expressions are one node
// (so common subexpressions are shared by construction), and the constructors fold constants
// and trivial identities (x*0, x+0, x*1, -(-x), ...) as nodes are made. Children always have
// smaller ids than their parents, so increasing id order is a topological order.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace symoro::codegen {

using NodeId = std::int32_t;

enum class Op : std::uint8_t {
  Constant,  // value
  Symbol,    // symbol index
  Add,       // a + b (commutative: operands ordered)
  Sub,       // a - b
  Mul,       // a * b (commutative: operands ordered)
  Div,       // a / b
  Neg,       // -a
  Pow,       // a ** value, value a constant exponent
  Sin,
  Cos,
  Sign,  // -1, 0, +1
  Exp,   // e ** a
  Tanh,  // hyperbolic tangent (smooth Coulomb friction)
};

struct Node {
  Op op = Op::Constant;
  NodeId a = -1;
  NodeId b = -1;
  double value = 0.0;  // Constant: the value; Pow: the exponent
  int symbol = -1;     // Symbol: index into the symbol table
};

class ExprGraph {
 public:
  ExprGraph();

  NodeId constant(double v);
  NodeId symbol(const std::string& name);
  NodeId add(NodeId a, NodeId b);
  NodeId sub(NodeId a, NodeId b);
  NodeId mul(NodeId a, NodeId b);
  NodeId div(NodeId a, NodeId b);
  NodeId neg(NodeId a);
  NodeId pow(NodeId a, double exponent);
  NodeId sin(NodeId a);
  NodeId cos(NodeId a);
  NodeId sign(NodeId a);
  NodeId exp(NodeId a);
  NodeId tanh(NodeId a);

  NodeId zero() const { return zero_; }
  NodeId one() const { return one_; }

  const Node& node(NodeId id) const { return nodes_[static_cast<std::size_t>(id)]; }
  std::size_t size() const { return nodes_.size(); }
  bool is_constant(NodeId id) const { return node(id).op == Op::Constant; }
  bool is_constant(NodeId id, double v) const { return is_constant(id) && node(id).value == v; }
  const std::string& symbol_name(int symbol) const { return symbols_[symbol]; }
  // The node of a symbol if it was ever made, else -1.
  NodeId find_symbol(const std::string& name) const;

 private:
  NodeId intern(Node n);
  bool negative_scaled(NodeId id) const;

  struct Key {
    Op op;
    NodeId a, b;
    std::uint64_t bits;  // value bits
    int symbol;
    bool operator==(const Key& o) const {
      return op == o.op && a == o.a && b == o.b && bits == o.bits && symbol == o.symbol;
    }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };

  std::vector<Node> nodes_;
  std::unordered_map<Key, NodeId, KeyHash> index_;
  std::vector<std::string> symbols_;
  std::unordered_map<std::string, int> symbol_index_;
  NodeId zero_, one_;
};

}  // namespace symoro::codegen
