# Runs under godot3-server (`-s res://fishgen_pose.gd`) in a project whose files were imported just
# before. Plays each clip named in res://fishgen_pose.json with the file's AnimationPlayer (seek, as
# a game's player does) and prints one line, `FISHGEN_POSE {...}`: for every mesh surface its
# triangles, vertices, normals, bone indices and weights, and its blend shapes' vertices and normals
# (as imported); and per clip and time the blend shape weights and each bind's skinning matrix
# (bone global pose x bind pose) the player left. engine_clients.godot_play() poses them.
extends SceneTree


func _init():
	var f = File.new()
	if f.open("res://fishgen_pose.json", File.READ) != OK:
		printerr("FISHGEN_FATAL cannot read res://fishgen_pose.json")
		quit(2)
		return
	var spec = parse_json(f.get_as_text())
	f.close()
	var res = load(spec["file"])
	if res == null:
		printerr("FISHGEN_FATAL load() returned null")
		quit(2)
		return
	var root = res.instance()
	get_root().add_child(root)
	var meshes = []
	var player = null
	for node in walk(root, []):
		if node is MeshInstance and node.mesh != null:
			meshes.append(node)
		elif node is AnimationPlayer:
			player = node
	var out = {"meshes": [], "clips": {}}
	for mi in meshes:
		out["meshes"].append(mesh_data(mi))
	for clip in spec["clips"]:
		var frames = []
		player.play(clip)
		for t in spec["clips"][clip]:
			player.seek(t, true)
			var state = []
			for mi in meshes:
				state.append(pose_of(mi))
			frames.append(state)
		player.stop()
		out["clips"][clip] = frames
	print("FISHGEN_POSE " + to_json(out))
	quit()


func walk(node, found):
	found.append(node)
	for child in node.get_children():
		walk(child, found)
	return found


func flat3(points):
	var out = []
	for p in points:
		out.append(p.x)
		out.append(p.y)
		out.append(p.z)
	return out


func mesh_data(mi):
	var mesh = mi.mesh
	var info = {"name": mi.name, "path": str(mi.get_path()), "shapes": [], "surfaces": [],
				"mode": mesh.blend_shape_mode if mesh is ArrayMesh else -1}
	for b in range(mesh.get_blend_shape_count()):
		info["shapes"].append(mesh.get_blend_shape_name(b))
	for s in range(mesh.get_surface_count()):
		var arrays = mesh.surface_get_arrays(s)
		var surf = {"index": Array(arrays[Mesh.ARRAY_INDEX]), "vertices": flat3(arrays[Mesh.ARRAY_VERTEX]),
					"normals": flat3(arrays[Mesh.ARRAY_NORMAL]), "bones": null, "weights": null,
					"blend": []}
		if arrays[Mesh.ARRAY_BONES] != null:
			surf["bones"] = Array(arrays[Mesh.ARRAY_BONES])
			surf["weights"] = Array(arrays[Mesh.ARRAY_WEIGHTS])
		if mesh is ArrayMesh and mesh.get_blend_shape_count() > 0:
			for shape in mesh.surface_get_blend_shape_arrays(s):
				surf["blend"].append({"vertices": flat3(shape[Mesh.ARRAY_VERTEX]),
									  "normals": flat3(shape[Mesh.ARRAY_NORMAL])})
		info["surfaces"].append(surf)
	return info


func pose_of(mi):
	var state = {"weights": [], "binds": []}
	for b in range(mi.mesh.get_blend_shape_count()):
		state["weights"].append(mi.get("blend_shapes/" + mi.mesh.get_blend_shape_name(b)))
	var skel = mi.get_node_or_null(mi.skeleton) if not mi.skeleton.is_empty() else null
	if skel is Skeleton and mi.skin != null:
		for b in range(mi.skin.get_bind_count()):
			var bone = mi.skin.get_bind_bone(b)
			if bone < 0:
				bone = skel.find_bone(mi.skin.get_bind_name(b))
			var xf = skel.get_bone_global_pose(bone) * mi.skin.get_bind_pose(b)
			state["binds"].append([xf.basis.x.x, xf.basis.x.y, xf.basis.x.z, xf.basis.y.x, xf.basis.y.y,
								   xf.basis.y.z, xf.basis.z.x, xf.basis.z.y, xf.basis.z.z,
								   xf.origin.x, xf.origin.y, xf.origin.z])
	return state
