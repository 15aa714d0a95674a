// Version string of the node library (the node types arrive with issues 4 and 5).
namespace vista {
const char* nodesVersion() { return "1"; }
}  // namespace vista
