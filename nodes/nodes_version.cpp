// Version string of the node library (the far-field and bake node types).
namespace vista {
const char* nodesVersion() { return "1"; }
}  // namespace vista
