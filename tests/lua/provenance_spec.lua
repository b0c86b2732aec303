-- provenance_spec.lua — every image written from Lua carries its
-- provenance (scene, --set parameters, seed, version) as metadata, read
-- back here with OpenImageIO's own `oiiotool --info -v`; and the options
-- of image:write (bits, meta).
local oc = require "outcrop"
local Fs = require "helpers.files"
local read_file = Fs.read_file
local info = Fs.image_info
local R = require "helpers.ref"

local F = "provenance_spec.lua"
local reg = debug.getregistry()
local node = oc.point{center = {0, 0, 0}, radius = 1}



-- A quoted value of a description line, as the README documents it.
local function unquote(v)
  if v:sub(1, 1) ~= '"' then return v end
  assert(v:sub(-1) == '"' and #v >= 2, v)
  local esc = {n = "\n", t = "\t", r = "\r", ['"'] = '"', ["\\"] = "\\"}
  return (v:sub(2, -2):gsub("\\(%d%d%d)", function(d)
    return string.char(tonumber(d, 8))
  end):gsub("\\(.)", esc))
end

-- The "key=value" lines folded into a TIFF or JPEG ImageDescription.
local function description_lines(text)
  local d = text:match('ImageDescription: "(.-)"\n%s+%w')
  local t = {}
  for line in (d or ""):gmatch("[^\n]+") do
    local k, v = line:match("^([^=]+)=(.*)$")
    if k then
      assert(t[k] == nil, "line repeated: " .. k)
      t[k] = unquote(v)
    end
  end
  return t
end

-- SHA-256 of a file by coreutils, independently of the engine.
local function sha256sum(path)
  local p = assert(io.popen("sha256sum '" .. path .. "'"))
  local h = p:read("a"):match("^(%x+)")
  p:close()
  assert(h and #h == 64, "sha256sum failed on " .. path)
  return h
end

local function write_text(path, text)
  local f = assert(io.open(path, "w"))
  f:write(text)
  f:close()
end

describe("provenance", function()
  local dir
  before_each(function() dir = R.tmpdir(); R.reset_config() end)
  after_each(function()
    R.rmdir(dir)
    R.reset_config()
  end)

  it("under stock lua5.4: the script's file, no parameters, seed 1", function()
    -- a script run by lua5.4 itself, as a user would (busted's own main
    -- chunk is not a scene)
    local script = dir .. "/scene.lua"
    local f = assert(io.open(script, "w"))
    f:write([[
local oc = require "outcrop"
local function out(name)
  return oc.slice(oc.point{center = {0, 0, 0}, radius = 1}, {size = {4, 4}})
    :write(name)
end
assert(out(arg[1]))
]])
    f:close()
    assert.is_true(os.execute("cd '" .. dir .. "' && lua5.4 scene.lua a.png"))
    local a = info(dir .. "/a.png")
    assert.are.equal("outcrop " .. oc.version, a.Software)
    assert.are.equal(oc.version, a["outcrop:version"])
    assert.are.equal("scene.lua", a["outcrop:scene"])
    assert.are.equal(sha256sum(script), a["outcrop:scene_sha256"])
    assert.are.equal("1", a["outcrop:seed"])
    assert.are.equal("(none)", a["outcrop:params"])
    assert.are.equal("(none)", a["outcrop:inputs"])
  end)

  it("under stock lua5.4 with outcrop.configure: seed, every parameter, the scene's and the inputs' hashes", function()
    -- two input files, one read twice; a name with a space is quoted
    assert(oc.heightfield.fbm{size = {8, 8}, wavelength = 4,
      amplitude = 2, seed = 3}:save(dir .. "/in one.png"))
    assert(oc.heightfield.fbm{size = {8, 8}, wavelength = 4,
      amplitude = 2, seed = 4}:save(dir .. "/two.exr"))
    local script = dir .. "/scene.lua"
    write_text(script, [[
local oc = require "outcrop"
oc.configure{seed = 7, params = {steps = 6, name = "big arch", fast = true}}
local steps, cell = oc.param("steps", 4), oc.param("cell", 0.8)
assert(steps == 6 and cell == 0.8 and oc.param("fast") == true)
assert(oc.param("rocks", 240) == 240 and oc.param("none") == nil)
assert(oc.param("third", 1 / 3) == 1 / 3)
assert(oc.seed == 7)
oc.heightfield.load("two.exr")
oc.heightfield.load("in one.png")
oc.heightfield.load("two.exr")
assert(oc.slice(oc.point{center = {0, 0, 0}, radius = 1}, {size = {4, 4}})
  :write(arg[1]))
]])
    assert.is_true(os.execute("cd '" .. dir .. "' && lua5.4 scene.lua a.png"))
    local a = info(dir .. "/a.png")
    assert.are.equal("scene.lua", a["outcrop:scene"])
    assert.are.equal(sha256sum(script), a["outcrop:scene_sha256"])
    assert.are.equal("7", a["outcrop:seed"])
    -- defaults included, as --set would spell them; "none" (no default,
    -- not set) is left out; 1/3 keeps all its digits
    assert.are.equal('cell=0.8 fast=true "name=big arch" rocks=240 '
      .. "steps=6 third=0.33333333333333331", a["outcrop:params"])
    assert.are.equal("two.exr=" .. sha256sum(dir .. "/two.exr") ..
      ' "in one.png=' .. sha256sum(dir .. "/in one.png") .. '"',
      a["outcrop:inputs"])
  end)

  it("records a changed input file again, with its new hash", function()
    local hf = oc.heightfield.fbm{size = {8, 8}, wavelength = 4, amplitude = 2}
    local path = dir .. "/in.png"
    assert(hf:save(path))
    local h1 = sha256sum(path)
    oc.heightfield.load(path)
    assert(oc.heightfield.fbm{size = {8, 8}, wavelength = 4,
      amplitude = 2, seed = 99}:save(path))
    local h2 = sha256sum(path)
    assert.are_not.equal(h1, h2)
    oc.heightfield.load(path)
    oc.heightfield.load(path)
    assert.is_true(oc.slice(node, {size = {2, 2}}):write(dir .. "/o.png"))
    assert.are.equal(path .. "=" .. h1 .. " " .. path .. "=" .. h2,
      info(dir .. "/o.png")["outcrop:inputs"])
  end)

  it("records the interpreter's scene, sorted parameters and seed", function()
    reg["outcrop.scene"] = "scenes/arch.lua"
    reg["outcrop.seed"] = 42
    reg["outcrop.params"] = {zeta = "1", alpha = "two words", b = 'q"x',
      c = "tab\there", ["d e"] = "f", eq = "x=y"}
    local img = oc.slice(node, {size = {4, 4}})
    local want = '"alpha=two words" "b=q\\"x" "c=tab\\there" "d e=f" eq=x=y zeta=1'
    for _, ext in ipairs{"png", "exr"} do
      local path = dir .. "/p." .. ext
      assert.is_true(img:write(path))
      local a = info(path)
      assert.are.equal("scenes/arch.lua", a["outcrop:scene"], ext)
      assert.are.equal("42", a["outcrop:seed"], ext)
      assert.are.equal(want, a["outcrop:params"], ext)
      assert.are.equal(oc.version, a["outcrop:version"], ext)
    end
    -- TIFF and JPEG have no free text fields: the keys become lines of
    -- the ImageDescription
    for _, ext in ipairs{"tif", "jpg"} do
      local path = dir .. "/p." .. ext
      assert.is_true(img:write(path))
      local _, text = info(path)
      local d = description_lines(text)
      assert.are.equal("scenes/arch.lua", d["outcrop:scene"], ext)
      assert.are.equal("42", d["outcrop:seed"], ext)
      assert.are.equal(want, d["outcrop:params"], ext)
    end
  end)

  it("cannot be forged by a line break in a scene name or a parameter", function()
    local forged = "scenes/a.lua\noutcrop:seed=99"
    reg["outcrop.scene"] = forged
    reg["outcrop.seed"] = 42
    reg["outcrop.params"] = {p = "1\noutcrop:seed=99"}
    local img = oc.slice(node, {size = {4, 4}})
    for _, ext in ipairs{"tif", "jpg"} do
      local path = dir .. "/forge." .. ext
      assert.is_true(img:write(path))
      local _, text = info(path)
      local d = description_lines(text)
      assert.are.equal("42", d["outcrop:seed"], ext)
      assert.are.equal(forged, d["outcrop:scene"], ext)
      assert.are.equal('"p=1\\noutcrop:seed=99"', d["outcrop:params"], ext)
    end
    for _, ext in ipairs{"png", "exr"} do
      local path = dir .. "/forge." .. ext
      assert.is_true(img:write(path))
      local a = info(path)
      assert.are.equal("42", a["outcrop:seed"], ext)
    end
  end)

  it("is byte-identical whatever order the parameters were set in", function()
    local names = {}
    for i = 1, 40 do names[i] = "p" .. i end
    local function write(path, order)
      local t = {}
      for _, i in ipairs(order) do t[names[i]] = tostring(i) end
      reg["outcrop.params"] = t
      assert.is_true(oc.slice(node, {size = {4, 4}}):write(path))
    end
    local fwd, back = {}, {}
    for i = 1, 40 do fwd[i], back[i] = i, 41 - i end
    write(dir .. "/f.png", fwd)
    write(dir .. "/b.png", back)
    assert.are.equal(read_file(dir .. "/f.png"), read_file(dir .. "/b.png"))
    local a = info(dir .. "/f.png")
    assert.is_truthy(a["outcrop:params"]:find("^p1=1 p10=10 p11=11 "))
  end)

  it("cuts an enormous parameter list with a marker", function()
    reg["outcrop.params"] = {a = string.rep("x", 40000), b = string.rep("y", 40000)}
    local path = dir .. "/big.exr"
    assert.is_true(oc.slice(node, {size = {2, 2}}):write(path))
    local v = info(path)["outcrop:params"]
    -- (compared by length and ends: a failure must not print 40 kB)
    assert.are.equal(40006, #v)
    assert.are.equal("a=xxx", v:sub(1, 5))
    assert.are.equal("x ...", v:sub(-5))
  end)

  it("stamps again on each write (values follow the registry)", function()
    local img = oc.slice(node, {size = {2, 2}})
    reg["outcrop.seed"] = 5
    assert.is_true(img:write(dir .. "/s5.png"))
    reg["outcrop.seed"] = 6
    assert.is_true(img:write(dir .. "/s6.png"))
    assert.are.equal("5", info(dir .. "/s5.png")["outcrop:seed"])
    assert.are.equal("6", info(dir .. "/s6.png")["outcrop:seed"])
  end)
end)

describe("image:write options", function()
  local dir
  local img = oc.slice(node, {size = {3, 2}})
  before_each(function() dir = R.tmpdir() end)
  after_each(function() R.rmdir(dir) end)

  it("adds the caller's metadata, sorted, beside the provenance", function()
    assert.is_true(img:write(dir .. "/m.exr", {meta = {note = "hello", n = 3}}))
    local a = info(dir .. "/m.exr")
    assert.are.equal("hello", a.note)
    assert.are.equal("3", a.n)
    assert.are.equal(oc.version, a["outcrop:version"])
  end)

  it("checks meta", function()
    local p = dir .. "/x.png"
    R.check_error(function() img:write(p, {meta = 5}) end, F, "image:write", "'meta' must be a table")
    R.check_error(function() img:write(p, {meta = {[1] = "a"}}) end, F, "image:write", "'meta' keys must be strings")
    R.check_error(function() img:write(p, {meta = {k = {}}}) end, F, "image:write", "'meta.k' must be a string or a number")
    R.check_error(function() img:write(p, {meta = {["outcrop:seed"] = "9"}}) end, F, "image:write", "'meta.outcrop:seed' is provenance")
    R.check_error(function() img:write(p, {meta = {Software = "x"}}) end, F, "image:write", "'meta.Software' is provenance")
    R.check_error(function() img:write(p, {meta = {compression = "none"}}) end, F, "image:write", "'meta.compression'", "reserved")
    R.check_error(function() img:write(p, {meta = {["a b"] = "x"}}) end, F, "image:write", "'meta.a b'", "may hold only")
    assert.is_nil(read_file(p))
  end)

  it("writes float TIFF and EXR with bits = 32, refuses it for PNG", function()
    assert.is_true(img:write(dir .. "/f.tif", {bits = 32}))
    assert.is_true(img:write(dir .. "/f.exr", {bits = 32}))
    local _, t = info(dir .. "/f.tif")
    assert.is_truthy(t:find("float tiff", 1, true))
    local _, e = info(dir .. "/f.exr")
    assert.is_truthy(e:find("float openexr", 1, true))
    local _, h = info((img:write(dir .. "/h.exr") and dir .. "/h.exr"))
    assert.is_truthy(h:find("half openexr", 1, true))
    R.check_error(function() img:write(dir .. "/f.png", {bits = 32}) end, F, "image:write", "'bits' must be 8 or 16 for PNG")
    R.check_error(function() img:write(dir .. "/f.jpg", {bits = 16}) end, F, "image:write", "'bits' must be 8 for JPEG")
    R.check_error(function() img:write(dir .. "/f.png", {bits = 12}) end, F, "image:write", "'bits' must be 8 or 16", "(got 12)")
    assert.is_nil(read_file(dir .. "/f.png"))
  end)

  it("writes 16-bit PNG and JPEG", function()
    assert.is_true(img:write(dir .. "/b.png", {bits = 16}))
    assert.are.equal(16, read_file(dir .. "/b.png"):byte(25))
    assert.is_true(img:write(dir .. "/c.jpg"))
    assert.are.equal("\255\216", read_file(dir .. "/c.jpg"):sub(1, 2))
  end)
end)
