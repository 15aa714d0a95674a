// osgdb_vista: the osgDB plugin that lets stock OpenSceneGraph tools (osgviewer,
// osgconv, ...) read and write scenes containing vista's node types.
//
// The module carries the whole vista_nodes library (linked as a whole archive),
// so the REGISTER_OBJECT_WRAPPER objects in nodes/point_impostor.cpp
// ("vista::PointImpostor") and nodes/view_cell_switch.cpp ("vista::ViewCellSwitch")
// run when osgDB loads the module and add their wrappers to
// osgDB::ObjectWrapperManager. osgDB loads it on its own the first time an input or
// output stream meets an unknown class "vista::..." (see docs/reference/plugin.md for the
// search order and paths). There is no ReaderWriter: the files stay ordinary
// .osgb/.osgt/.osgx, read by OSG's own osgdb_osg plugin.
//
// NearFarSplit and FarFieldNode are runtime-only (built by `vista view` from the
// city file and a RayScene that must outlive the node) and have no wrapper; they
// are never written to files.
//
// Thread safety / errors: nothing here runs after load; bad data in a loaded file
// is the node classes' business (ViewCellSwitch::validate()).

namespace vista {

// Identifies the module (e.g. `nm -D osgdb_vista.so | grep vistaPluginName`).
extern "C" __attribute__((visibility("default"))) const char* vistaPluginName() { return "osgdb_vista"; }

}  // namespace vista
