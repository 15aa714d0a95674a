// STUB
namespace vista {}
