# Runs under godot3-server (`-s res://inspect.gd`) in a project whose files were
# imported just before. Loads each file named in res://fishgen_files.txt the way a
# game does (`load()`, `instance()`), and prints one line per file,
# `FISHGEN_JSON {...}`: every mesh (surfaces, counts, bounds of the vertices and of
# each blend shape, materials and their textures), node transforms, and every
# animation with its tracks, whether each track's node exists, and the range of its
# keys. tests/clients/godot.py compares these with what fishgen made.
extends SceneTree

const SAMPLES = 32


func _init():
	var f = File.new()
	if f.open("res://fishgen_files.txt", File.READ) != OK:
		printerr("FISHGEN_FATAL cannot read res://fishgen_files.txt")
		quit(2)
		return
	var paths = f.get_as_text().strip_edges().split("\n")
	f.close()
	for p in paths:
		print("FISHGEN_BEGIN " + p)  # what Godot prints from here on is about this file
		print("FISHGEN_JSON " + to_json(inspect(p)))
	quit()


func inspect(path):
	var res = load(path)
	if res == null:
		return {"file": path, "error": "load() returned null"}
	var out = {"file": path, "class": res.get_class(), "meshes": [], "animations": []}
	var root
	if res is PackedScene:
		root = res.instance()
	elif res is Mesh:  # an OBJ imports as a Mesh resource; a game puts it in a MeshInstance
		root = MeshInstance.new()
		root.mesh = res
	else:
		out["error"] = "unexpected resource " + res.get_class()
		return out
	get_root().add_child(root)
	walk(root, out)
	get_root().remove_child(root)
	root.free()
	return out


func walk(node, out):
	if node is MeshInstance and node.mesh != null:
		out["meshes"].append(mesh_info(node))
	if node is AnimationPlayer:
		for name in node.get_animation_list():
			out["animations"].append(animation_info(node, name))
	for child in node.get_children():
		walk(child, out)


func aabb_of(points):
	if points.size() == 0:
		return null
	var lo = points[0]
	var hi = points[0]
	for p in points:
		lo = Vector3(min(lo.x, p.x), min(lo.y, p.y), min(lo.z, p.z))
		hi = Vector3(max(hi.x, p.x), max(hi.y, p.y), max(hi.z, p.z))
	return [[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]]


func world_aabb(points, xform):
	var moved = PoolVector3Array()
	for p in points:
		moved.append(xform.xform(p))
	return aabb_of(moved)


func texture_info(tex):
	if tex == null:
		return null
	return {"class": tex.get_class(), "width": tex.get_width(), "height": tex.get_height(),
			"path": tex.resource_path}


func material_info(m):
	if m == null:
		return null
	var info = {"class": m.get_class(), "name": m.resource_name, "path": m.resource_path}
	if m is SpatialMaterial:
		info["albedo_texture"] = texture_info(m.albedo_texture)
		info["transparent"] = m.flags_transparent
		info["alpha_scissor"] = m.params_use_alpha_scissor
		info["alpha_scissor_threshold"] = m.params_alpha_scissor_threshold
		info["cull_mode"] = m.params_cull_mode
		info["vertex_color_use_as_albedo"] = m.vertex_color_use_as_albedo
		info["use_point_size"] = m.flags_use_point_size
		info["unshaded"] = m.flags_unshaded
	return info


func mesh_info(mi):
	var mesh = mi.mesh
	var xform = mi.global_transform
	var info = {"node": str(mi.get_path()), "name": mi.name, "mesh": mesh.resource_name,
				"mesh_id": mesh.get_instance_id(),
				"transform": [xform.basis.x.x, xform.basis.x.y, xform.basis.x.z,
							  xform.basis.y.x, xform.basis.y.y, xform.basis.y.z,
							  xform.basis.z.x, xform.basis.z.y, xform.basis.z.z,
							  xform.origin.x, xform.origin.y, xform.origin.z],
				"blend_shapes": mesh.get_blend_shape_count(), "surfaces": []}
	if mesh is ArrayMesh:
		info["blend_shape_mode"] = mesh.blend_shape_mode
	info["blend_shape_names"] = []
	for b in range(mesh.get_blend_shape_count()):
		info["blend_shape_names"].append(mesh.get_blend_shape_name(b))
	# a skinned mesh: the bones of its skin (the skin's binds, by bone name), on the skeleton it names
	var skel = mi.get_node_or_null(mi.skeleton) if not mi.skeleton.is_empty() else null
	if skel is Skeleton:
		info["skeleton"] = str(skel.get_path())
		info["bones"] = []
		if mi.skin != null:
			for b in range(mi.skin.get_bind_count()):
				var bone = mi.skin.get_bind_bone(b)
				info["bones"].append(mi.skin.get_bind_name(b) if bone < 0 else skel.get_bone_name(bone))
		else:
			for b in range(skel.get_bone_count()):
				info["bones"].append(skel.get_bone_name(b))
	info["visible"] = mi.is_visible_in_tree()
	for s in range(mesh.get_surface_count()):
		var arrays = mesh.surface_get_arrays(s)
		var verts = arrays[Mesh.ARRAY_VERTEX]
		var index = arrays[Mesh.ARRAY_INDEX]
		var mat = mi.get_surface_material(s)
		if mat == null:
			mat = mesh.surface_get_material(s)
		var surf = {"primitive": mesh.surface_get_primitive_type(s), "vertices": verts.size(),
					"indices": index.size() if index != null else 0,
					"has_uv": arrays[Mesh.ARRAY_TEX_UV] != null,
					"has_color": arrays[Mesh.ARRAY_COLOR] != null,
					"aabb": aabb_of(verts), "world_aabb": world_aabb(verts, xform),
					"material": material_info(mat), "blend_aabbs": []}
		if mesh is ArrayMesh and mesh.get_blend_shape_count() > 0:
			for shape in mesh.surface_get_blend_shape_arrays(s):
				surf["blend_aabbs"].append(aabb_of(shape[Mesh.ARRAY_VERTEX]))
		info["surfaces"].append(surf)
	return info


func animation_info(player, name):
	# Every key of every track, so the test can compare each with fishgen's clip at that time:
	# transform keys [t, x, y, z, qx, qy, qz, qw, sx, sy, sz], value keys [t, v].
	var anim = player.get_animation(name)
	var base = player.get_node(player.root_node)
	var info = {"name": name, "length": anim.length, "loop": anim.loop, "tracks": []}
	for t in range(anim.get_track_count()):
		var path = str(anim.track_get_path(t))
		var target = base.get_node_or_null(NodePath(path.split(":")[0]))
		var track = {"path": path, "type": anim.track_get_type(t), "bound": target != null, "keys": []}
		# a bone's keys are poses relative to its rest: as the glTF node's transform, rest * pose
		var bone = bone_of(target, path)
		if bone >= 0:
			track["bone"] = target.get_bone_name(bone)
		elif target is Skeleton:
			track["bound"] = false
		for k in range(anim.track_get_key_count(t)):
			var time = anim.track_get_key_time(t, k)
			var v = anim.track_get_key_value(t, k)
			if anim.track_get_type(t) == Animation.TYPE_TRANSFORM:
				var xf = Transform(Basis(v["rotation"]).scaled(v["scale"]), v["location"])
				if bone >= 0:
					xf = target.get_bone_rest(bone) * xf
				track["keys"].append(transform_key(time, xf))
			else:
				track["keys"].append([time, v])
		if anim.track_get_type(t) == Animation.TYPE_VALUE and target != null and path.find(":") >= 0:
			track["property_exists"] = target.get(path.split(":", true, 1)[1]) != null
		info["tracks"].append(track)
	# and as the player plays it: seek to SAMPLES + 1 times over the clip and read each animated
	# node's transform and blend shape weights, as a game would see them
	player.play(name)
	for i in range(SAMPLES + 1):
		var time = anim.length * i / SAMPLES
		player.seek(time, true)
		for track in info["tracks"]:
			var parts = track["path"].split(":", true, 1)
			var target = base.get_node_or_null(NodePath(parts[0]))
			if not track.has("played"):
				track["played"] = []
			if target == null:
				continue
			if track["type"] == Animation.TYPE_TRANSFORM:
				var xf = target.transform
				if track.has("bone"):
					var b = target.find_bone(track["bone"])
					xf = target.get_bone_rest(b) * target.get_bone_custom_pose(b) * target.get_bone_pose(b)
				track["played"].append(transform_key(time, xf))
			else:
				track["played"].append([time, target.get(parts[1])])
	player.stop()
	return info


func bone_of(target, path):
	# the bone a track `Skeleton:bone` drives, else -1
	if not (target is Skeleton) or path.find(":") < 0:
		return -1
	return target.find_bone(path.split(":", true, 1)[1])


func transform_key(time, xf):
	var q = Quat(xf.basis.orthonormalized())
	var sc = xf.basis.get_scale()
	return [time, xf.origin.x, xf.origin.y, xf.origin.z, q.x, q.y, q.z, q.w, sc.x, sc.y, sc.z]
