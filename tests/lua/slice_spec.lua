-- slice_spec.lua — outcrop.slice and the image userdata: sizes, pixel
-- positions, writing, and the output-folder sandbox of oclua_output_target.
local oc = require "outcrop"
local Fs = require "helpers.files"
local read_file = Fs.read_file
local R = require "helpers.ref"

local F = "slice_spec.lua"
local reg = debug.getregistry()
local node = oc.point{center = {0.5, 0.25, -0.5}, radius = 2} +
  oc.box{min = {-1, -1, -1}, max = {0, 0, 0}, falloff = 0.5}


describe("outcrop.slice", function()
  it("samples the documented pixel centres (plane xz)", function()
    local img = oc.slice(node, {plane = "xz", at = 0.25, box = {-2, -3, 2, 1},
      size = {16, 8}})
    local w, h = img:size()
    assert.are.equal(16, w)
    assert.are.equal(8, h)
    assert.are.equal(5, img:channels())
    for _, ij in ipairs{{1, 1}, {16, 8}, {5, 3}, {12, 6}, {8, 8}} do
      local i, j = ij[1], ij[2]
      local u = -2 + (i - 0.5) * 4 / 16
      local v = 1 - (j - 0.5) * 4 / 8
      local vals = {img:get(i, j)}
      assert.are.equal(5, #vals)
      R.close(vals[5], node:eval(u, 0.25, v), 1e-6, "field at " .. i .. "," .. j)
      for c = 1, 4 do assert.is_true(vals[c] >= 0 and vals[c] <= 1) end
    end
  end)

  it("maps the planes xy and yz", function()
    local a = oc.slice(node, {plane = "xy", at = -0.5, box = {-1, -1, 1, 1}, size = {4, 4}})
    R.close(select(5, a:get(2, 3)), node:eval(-0.25, -0.25, -0.5), 1e-6)
    local b = oc.slice(node, {plane = "yz", at = 0.1, box = {-1, -1, 1, 1}, size = {4, 4}})
    R.close(select(5, b:get(4, 1)), node:eval(0.1, 0.75, 0.75), 1e-6)
  end)

  it("defaults: plane xz, at 0, 256x256, box from the bounds", function()
    local p = oc.point{center = {0, 0, 0}, radius = 1}
    local img = oc.slice(p)
    local w, h = img:size()
    assert.are.equal(256, w)
    assert.are.equal(256, h)
    -- an explicit nil is the same as no options
    assert.are.equal(256, (oc.slice(p, nil):size()))
    local x0, _, z0, x1, _, z1 = p:bounds()
    local i, j = 100, 40
    local u = x0 + (i - 0.5) * (x1 - x0) / 256
    local v = z1 - (j - 0.5) * (z1 - z0) / 256
    R.close(select(5, img:get(i, j)), p:eval(u, 0, v), 1e-6)
  end)

  it("checks its arguments", function()
    R.check_error(function() oc.slice(5) end, F, "outcrop.slice", "argument #1 must be an outcrop node")
    R.check_error(function() oc.slice(node, {plane = "xw"}) end, F, "outcrop.slice", "'plane' must be one of", "\"xz\"", "(got \"xw\")")
    R.check_error(function() oc.slice(node, {box = {1, 0, 0, 1}}) end, F, "outcrop.slice", "u0 < u1")
    R.check_error(function() oc.slice(node, {box = {0, 0, 1}}) end, F, "outcrop.slice", "'box'")
    R.check_error(function() oc.slice(node, {size = {0, 10}}) end, F, "outcrop.slice", "'size'")
    R.check_error(function() oc.slice(node, {size = {10, 20000}}) end, F, "outcrop.slice", "'size'")
    R.check_error(function() oc.slice(node, {size = {10.5, 10}}) end, F, "outcrop.slice", "'size'")
    R.check_error(function() oc.slice(node, {sise = {10, 10}}) end, F, "outcrop.slice", "unknown field 'sise'", "'size'")
    local t = oc.turbulence{wavelength = 1}
    R.check_error(function() oc.slice(t) end, F, "outcrop.slice", "infinite", "'box'")
  end)
end)

describe("image", function()
  local img = oc.slice(node, {box = {-2, -2, 2, 2}, size = {6, 4}})

  it("get checks its indices", function()
    R.check_error(function() img:get(0, 1) end, F, "image:get", "column", "1..6", "(got 0)")
    R.check_error(function() img:get(1, 5) end, F, "image:get", "row", "1..4", "(got 5)")
    R.check_error(function() img:get(1.5, 1) end, F, "image:get", "column")
    R.check_error(function() img:get(1) end, F, "image:get", "row")
  end)

  it("has a tostring", function()
    assert.are.equal("outcrop.image: 6x4, 5 channels", tostring(img))
  end)

  it("can be closed early with <close>", function()
    local saved
    do
      local im <close> = oc.slice(node, {box = {-1, -1, 1, 1}, size = {2, 2}})
      saved = im
    end
    R.check_error(function() saved:size() end, F, "image:size", "closed")
    assert.are.equal("outcrop.image: (closed)", tostring(saved))
  end)

  describe("write", function()
    local dir
    before_each(function() dir = R.tmpdir() end)
    after_each(function()
      R.rmdir(dir)
      reg["outcrop.outdir"], reg["outcrop.sandbox"] = nil, nil
    end)

    it("writes a PNG and returns true", function()
      local path = dir .. "/a.png"
      assert.is_true(img:write(path))
      local data = read_file(path)
      assert.are.equal("\137PNG", data:sub(1, 4))
      assert.are.equal(8, data:byte(25)) -- IHDR bit depth
    end)

    it("writes 16-bit PNG with {bits = 16}", function()
      local path = dir .. "/b.png"
      assert.is_true(img:write(path, {bits = 16}))
      assert.are.equal(16, read_file(path):byte(25))
    end)

    it("returns nil and a message for an unwritable path", function()
      local ok, msg = img:write("/proc/outcrop-no-such-dir/x.png")
      assert.is_nil(ok)
      assert.are.equal("string", type(msg))
      local f = io.open(dir .. "/a-file", "w"); f:close()
      ok, msg = img:write(dir .. "/a-file/x.png")
      assert.is_nil(ok)
      assert.is_true(#msg > 0)
    end)

    it("checks its options", function()
      R.check_error(function() img:write(5) end, F, "image:write", "path must be a string")
      R.check_error(function() img:write(dir .. "/c.png", {bits = 12}) end, F, "image:write", "'bits' must be 8 or 16")
      R.check_error(function() img:write(dir .. "/c.png", {depth = 8}) end, F, "image:write", "unknown field 'depth'")
    end)

    it("puts relative paths in the output folder and creates folders", function()
      reg["outcrop.outdir"] = dir
      assert.is_true(img:write("sub/deeper/r.png"))
      assert.is_not_nil(read_file(dir .. "/sub/deeper/r.png"))
    end)

    it("keeps writes inside the output folder in sandbox mode", function()
      reg["outcrop.outdir"] = dir .. "/out"
      reg["outcrop.sandbox"] = true
      assert.is_true(img:write("in/x.png"))
      assert.is_not_nil(read_file(dir .. "/out/in/x.png"))
      assert.is_true(img:write("in/../y.png"))
      assert.is_not_nil(read_file(dir .. "/out/y.png"))
      assert.is_true(img:write(dir .. "/out/z.png"))
      R.check_error(function() img:write("../escape.png") end, F, "image:write", "outside the output folder")
      R.check_error(function() img:write("a/../../escape.png") end, F, "image:write", "outside the output folder")
      R.check_error(function() img:write(dir .. "/escape.png") end, F, "image:write", "outside the output folder")
      R.check_error(function() img:write("/tmp/escape.png") end, F, "image:write", "outside the output folder")
      assert.is_nil(read_file(dir .. "/escape.png"))
      -- a symlink inside that leads outside
      assert(os.execute("ln -s '" .. dir .. "' '" .. dir .. "/out/link'"))
      R.check_error(function() img:write("link/escape.png") end, F, "image:write", "outside the output folder")
      assert.is_nil(read_file(dir .. "/escape.png"))
      assert(os.execute("ln -s '" .. dir .. "/target.png' '" .. dir .. "/out/file.png'"))
      R.check_error(function() img:write("file.png") end, F, "image:write", "outside the output folder")
    end)
  end)
end)
