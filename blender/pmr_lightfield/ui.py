"""The panel in Properties > Render."""

import bpy

from . import operators


class PMR_PT_lightfield(bpy.types.Panel):
    bl_label = "pmr Light Field"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        s = context.scene.pmr_lightfield
        layout = self.layout
        layout.use_property_split = True
        layout.prop(s, "display_source")
        if s.display_source == "PRESET":
            layout.prop(s, "preset")
        else:
            layout.prop(s, "display_config")
        col = layout.column(align=True)
        col.prop(s, "views")
        col.prop(s, "view_width")
        col.prop(s, "view_height")
        layout.prop(s, "sampling")
        layout.prop(s, "samples")
        layout.prop(s, "texture_filter")
        layout.prop(s, "environment")
        layout.prop(s, "shadow_catcher")
        layout.prop(s, "output_dir")
        layout.prop(s, "name")
        layout.prop(s, "write")
        layout.prop(s, "mode", expand=True)
        if s.mode == "SEQUENCE":
            layout.prop(s, "use_scene_range")
            if not s.use_scene_range:
                col = layout.column(align=True)
                col.prop(s, "frame_start")
                col.prop(s, "frame_end")
        layout.prop(s, "extra_args")
        row = layout.row()
        row.scale_y = 1.5
        if operators.running():
            row.operator("pmr.cancel_lightfield", icon="CANCEL")
        else:
            row.operator("pmr.render_lightfield", icon="RENDER_STILL")


CLASSES = [PMR_PT_lightfield]
