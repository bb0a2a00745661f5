# `xvfb-run godot3 --path P -s res://fishgen_render.gd` (tools/check_clients.py --look): draws every
# file named in res://fishgen_files.txt from the side, the front and above, as Godot 3 renders it
# with its defaults, into $FISHGEN_LOOK/godot-FOLDER-NAME-SIDE.png. For people to look at, not a test.
extends SceneTree

const SIDES = ["side", "front", "above"]
var jobs = []
var frame = 0
var current = null
var camera = null
var out = ""


func _init():
	out = OS.get_environment("FISHGEN_LOOK")
	var f = File.new()
	f.open("res://fishgen_files.txt", File.READ)
	for path in f.get_as_text().strip_edges().split("\n"):
		for side in SIDES:
			jobs.append([path, side])
	f.close()
	var env = Environment.new()
	env.background_mode = Environment.BG_COLOR
	env.background_color = Color(0.13, 0.19, 0.25)
	env.ambient_light_color = Color(0.5, 0.5, 0.5)
	var world = WorldEnvironment.new()
	world.environment = env
	get_root().add_child(world)
	var light = DirectionalLight.new()
	light.rotation_degrees = Vector3(-50, 30, 0)
	get_root().add_child(light)
	camera = Camera.new()
	get_root().add_child(camera)
	camera.current = true


func bounds(node, box):
	if node is MeshInstance:
		var b = node.global_transform.xform(node.get_aabb())
		box = b if box == null else box.merge(b)
	for child in node.get_children():
		box = bounds(child, box)
	return box


# Every third frame: save what the last one drew, then show the next file from the next side.
func _idle(_delta):
	frame += 1
	if frame % 3 != 1:
		return false
	if current != null:
		var job = jobs.pop_front()
		var img = get_root().get_texture().get_data()
		img.flip_y()
		var name = job[0].get_base_dir().get_file() + "-" + job[0].get_file().get_basename()
		img.save_png(out.plus_file("godot-" + name + "-" + job[1] + ".png"))
		current.queue_free()
		current = null
	if jobs.empty():
		quit()
		return false
	var job = jobs[0]
	var res = load(job[0])
	if res is PackedScene:
		current = res.instance()
	else:
		current = MeshInstance.new()
		current.mesh = res
	get_root().add_child(current)
	var box = bounds(current, null)
	var centre = box.position + box.size * 0.5
	var r = box.size.length() * 1.1
	var eye = {"side": Vector3(r, 0, 0), "front": Vector3(0, 0, r), "above": Vector3(0, r, 0)}[job[1]]
	camera.near = r / 100
	camera.far = r * 10
	camera.look_at_from_position(centre + eye, centre, Vector3(0, 0, -1) if job[1] == "above" else Vector3.UP)
	return false
