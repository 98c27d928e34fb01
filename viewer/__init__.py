"""``aarecovery view``: an interactive viewer for antialiasing recovery (the ``viewer`` extra).

A GLFW window whose OpenGL context the recovery engine borrows: the engine's textures are
drawn directly, with Dear ImGui (imgui-bundle) widgets on top. Modules, one idea each:

``view_state``     zoom, pan and split arithmetic (pure Python)
``glsl``           the GLSL sources (package resources)
``image_view``     the shader that draws images, maps, heat-maps and the split view
``imgui_renderer`` Dear ImGui's draw data drawn with moderngl
``glfw_platform``  GLFW input events fed to ImGui
``sources``        where the pair comes from: files, a built-in filter, the bundled sample
``settings``       the recovery parameters and the equivalent command line
``saving``         where R is saved and when to ask first
``keys``           the views and keys (help overlay and docs)
``ui``             the panel, messages, help overlay and dialogs
``app``            the window, the frame loop and the engine
``bench``          ``--bench``: frame time and slider-to-frame latency
``cli``            the ``view`` subcommand

Nothing here is imported by ``import aarecovery``; ``glfw`` is always imported before
``imgui_bundle`` (the first import decides which GLFW library loads).
"""
