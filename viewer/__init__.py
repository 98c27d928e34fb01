"""``aarecovery view``: an interactive viewer for antialiasing recovery (the ``viewer`` extra).

A GLFW window whose OpenGL context the recovery engine borrows: the engine's textures are
drawn directly, with Dear ImGui (imgui-bundle) widgets on top. Modules, one idea each:

``app``            the window's frame loop: polls input, builds the UI, drives the parts below
``window``         the GLFW window and its OpenGL 3.3 core context
``glfw_platform``  GLFW input events fed to ImGui
``imgui_renderer`` Dear ImGui's draw data drawn with moderngl
``ui``             the panel, messages, help overlay, dialogs and the split divider
``status``         the panel's status lines
``panel_state``    what the panel holds between frames: paths, filter, pending questions
``view_input``     mouse and keys: pan, zoom, the divider, the shortcuts
``keys``           the views and keys (help overlay and docs)
``view_state``     zoom, pan and split arithmetic (pure Python)
``comparison``     which view, what R is compared with, flicker; the layers to draw
``image_view``     the shader that draws images, maps, heat-maps and the split view
``glsl``           the GLSL sources (package resources)
``live_recovery``  the engine kept current: re-runs the recovery when the settings change
``settings``       the recovery parameters and the equivalent command line
``sources``        where the pair comes from: files, a built-in filter, the bundled sample
``opening``        opening a pair from a source, the panel's fields or dropped files
``saving``         saving R (asking first) and copying the command line
``file_dialogs``   native file dialogs, polled between frames
``messages``       errors and notes shown over the image
``bench``          ``--bench``: frame time and slider-to-frame latency
``cli``            the ``view`` subcommand

Nothing here is imported by ``import aarecovery``; ``glfw`` is always imported before
``imgui_bundle`` (the first import decides which GLFW library loads).
"""
