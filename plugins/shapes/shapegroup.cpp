static const char *DOC = R"DOC(
# shapegroup: shapes to be instanced

Groups shapes so that `instance` shapes can place copies of them. The group itself is not
rendered; each instance adds the whole group under its own transform, sharing one Embree
scene (memory is paid once). Nested shapes keep their BSDFs; emitters inside a group are not
supported.

| Parameter | Type  | Default | Description                        |
|-----------|-------|---------|------------------------------------|
| (nested)  | shape | —       | One or more shapes (not instances) |

```xml
<shape type="shapegroup" id="tree">
    <shape type="ply"> <string name="filename" value="tree.ply"/> </shape>
</shape>
<shape type="instance">
    <ref id="tree"/>
    <transform name="to_world"> <translate x="3"/> </transform>
</shape>
```
)DOC";

#include <facet/plugin.h>
#include <facet/shapegroup.h>

// The class lives in libfacet (facet/shapegroup.h) so that `instance` can use it.

FACET_EXPORT_PLUGIN_MODES(facet::ShapeGroup, Shape, "shapegroup",
                          "Group of shapes placed by instances", DOC, ::facet::AllModes)
