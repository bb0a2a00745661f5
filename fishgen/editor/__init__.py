"""`fishgen edit`: RekAwan's cloud cube editor as a local web page.

The page (``app.js``, bundled by tools/bundle_viewer.py; three.js comes from the page kit) holds the
cubes; the server (:mod:`fishgen.editor.session`) parses, fills, lights and saves them with
fishgen's own code, and reads or writes only the file it was given, cube files in that file's folder
and textures in the allowed texture folders (:mod:`fishgen.editor.workspace`).
:mod:`fishgen.editor.document` turns the page's cubes into cube file text.
"""
