-- param_spec.lua — outcrop.param, outcrop.configure, outcrop.seed and
-- outcrop.version, with the registry settings the interpreter would make
-- (oclua.h).
local oc = require "outcrop"
local R = require "helpers.ref"

local reg = debug.getregistry()

describe("outcrop.param", function()
  before_each(R.reset_config)
  after_each(R.reset_config)

  it("returns the default when no parameters are set", function()
    reg["outcrop.params"] = nil
    assert.are.equal(12, oc.param("size", 12))
    assert.is_nil(oc.param("size"))
    assert.are.equal("x", oc.param("name", "x"))
  end)

  it("parses numbers, booleans and strings", function()
    reg["outcrop.params"] = {size = "3", eps = "1e-2", hex = "0x10",
      flag = "true", off = "false", rock = "granite", neg = "-2.5",
      blank = "", spaced = " 7 "}
    assert.are.equal(3, oc.param("size", 1))
    assert.are.equal(math.type(oc.param("size")), "integer")
    assert.are.equal(0.01, oc.param("eps", 1))
    assert.are.equal(16, oc.param("hex"))
    assert.are.equal(true, oc.param("flag", false))
    assert.are.equal(false, oc.param("off", true))
    assert.are.equal("granite", oc.param("rock", "basalt"))
    assert.are.equal(-2.5, oc.param("neg"))
    assert.are.equal("", oc.param("blank", "d"))
    assert.are.equal(7, oc.param("spaced"))
    assert.are.equal("dflt", oc.param("absent", "dflt"))
  end)

  it("needs a string name and a string, number or boolean default", function()
    R.check_error(function() oc.param(3) end, "param_spec.lua", "outcrop.param", "name must be a string (got 3)")
    R.check_error(function() oc.param("a", 1, 2) end, "param_spec.lua", "outcrop.param", "too many arguments")
    R.check_error(function() oc.param("a", {}) end, "param_spec.lua", "outcrop.param", "default must be a string, a number or a boolean (got table)")
  end)
end)

describe("outcrop.configure", function()
  local F = "param_spec.lua"
  local C = "outcrop.configure"
  local dir
  before_each(function() R.reset_config(); dir = R.tmpdir() end)
  after_each(function()
    R.reset_config()
    reg["outcrop.sandbox"] = nil
    R.rmdir(dir)
  end)

  it("sets what outcrop.param and outcrop.seed return", function()
    local t = {steps = "6", eps = 0.25, name = "big arch", fast = true}
    oc.configure{seed = 42, params = t}
    assert.are.equal(6, oc.param("steps", 4))
    assert.are.equal("integer", math.type(oc.param("steps")))
    assert.are.equal(0.25, oc.param("eps", 1))
    assert.are.equal("big arch", oc.param("name"))
    assert.are.equal(true, oc.param("fast", false))
    assert.are.equal(3, oc.param("absent", 3))
    assert.are.equal(42, oc.seed)
    -- constructors without a seed take the configured one
    local a = oc.turbulence{wavelength = 1}
    local b = oc.turbulence{wavelength = 1, seed = 42}
    for i = 1, 10 do
      local p = {0.37 * i, 0.21 * i, -0.13 * i}
      assert.are.equal(b:eval(p), a:eval(p))
    end
    -- the caller's table is not kept or changed
    t.steps = "7"
    assert.are.equal(6, oc.param("steps"))
  end)

  it("makes relative writes resolve against out", function()
    oc.configure{out = dir}
    assert.is_true(oc.slice(oc.point{center = {0, 0, 0}, radius = 1},
      {size = {2, 2}}):write("o.png"))
    assert.is_truthy(io.open(dir .. "/o.png"))
  end)

  it("may repeat a value or add one, never change one", function()
    oc.configure{seed = 5, params = {a = "1"}}
    oc.configure{seed = 5, params = {a = 1, b = "x"}} -- "1" and 1 agree
    oc.configure{out = dir}
    oc.configure{out = dir .. "/."}
    assert.are.equal("x", oc.param("b"))
    R.check_error(function() oc.configure{seed = 6} end, F, C, "'seed' is already configured as 5 (got 6)")
    R.check_error(function() oc.configure{params = {a = "2"}} end, F, C, "'params.a' is already configured as \"1\" (got \"2\")")
    local other = dir .. "/other"
    assert(os.execute("mkdir '" .. other .. "'"))
    R.check_error(function() oc.configure{out = other} end, F, C, "'out' is already configured as")
    -- a refused call changes nothing, not even its valid fields
    R.check_error(function() oc.configure{params = {c = "3", a = "2"}} end, F, C, "already configured")
    assert.is_nil(oc.param("c"))
  end)

  it("comes before what it would change was used", function()
    assert.are.equal(4, oc.param("steps", 4))
    R.check_error(function() oc.configure{params = {steps = 6}} end, F, C, "'params.steps' comes too late: outcrop.param already read it")
    local _ = oc.seed
    R.check_error(function() oc.configure{seed = 9} end, F, C, "'seed' comes too late: the scene seed 1 was already used")
    oc.configure{seed = 1} -- the seed in use: nothing changes
    assert.is_true(oc.slice(oc.point{center = {0, 0, 0}, radius = 1},
      {size = {2, 2}}):write(dir .. "/w.png"))
    R.check_error(function() oc.configure{params = {other = 1}} end, F, C, "outputs were already written (configure before the first write)")
    R.check_error(function() oc.configure{out = dir} end, F, C, "outputs were already written")
  end)

  it("checks every field", function()
    R.check_error(function() oc.configure() end, F, C, "expects a table {seed =, params =, out =} (got no value)")
    R.check_error(function() oc.configure({}, 2) end, F, C, "too many arguments")
    R.check_error(function() oc.configure{sed = 1} end, F, C, "unknown field 'sed'")
    R.check_error(function() oc.configure{seed = -1} end, F, C, "'seed' must be an integer >= 0 (got -1)")
    R.check_error(function() oc.configure{seed = 1.5} end, F, C, "'seed' must be an integer >= 0 (got 1.5)")
    R.check_error(function() oc.configure{seed = "3"} end, F, C, "'seed' must be an integer >= 0")
    R.check_error(function() oc.configure{params = 3} end, F, C, "'params' must be a table {name = value} (got 3)")
    R.check_error(function() oc.configure{params = {1}} end, F, C, "'params' keys must be parameter names (got 1)")
    R.check_error(function() oc.configure{params = {[""] = 1}} end, F, C, "'params' names must be non-empty and hold no '='")
    R.check_error(function() oc.configure{params = {["a=b"] = 1}} end, F, C, "'params' names must be non-empty and hold no '=' (got \"a=b\")")
    R.check_error(function() oc.configure{params = {a = {}}} end, F, C, "'params.a' must be a string, a number or a boolean (got table)")
    R.check_error(function() oc.configure{params = {a = 1 / 0}} end, F, C, "'params.a' must be a finite number")
    R.check_error(function() oc.configure{out = 3} end, F, C, "'out' must be a string (a folder) (got 3)")
    R.check_error(function() oc.configure{out = dir .. "/none"} end, F, C, "'out' must name an existing folder", "No such file")
    local file = dir .. "/f"
    assert(io.open(file, "w")):close()
    R.check_error(function() oc.configure{out = file} end, F, C, "is not a folder")
    -- nothing was set by the refused calls
    assert.are.equal(1, oc.seed)
    assert.is_nil(reg["outcrop.params"])
    assert.is_nil(reg["outcrop.outdir"])
  end)

  it("cannot move the output folder of the sandbox", function()
    reg["outcrop.sandbox"] = true
    R.check_error(function() oc.configure{out = dir} end, F, C, "'out' cannot be set in the sandbox")
    oc.configure{seed = 3} -- the rest is allowed
    assert.are.equal(3, oc.seed)
  end)
end)

describe("outcrop.seed", function()
  local saved
  before_each(function() saved = reg["outcrop.seed"] end)
  after_each(function() R.reset_config(); reg["outcrop.seed"] = saved end)

  it("defaults to 1", function()
    reg["outcrop.seed"] = nil
    assert.are.equal(1, oc.seed)
  end)

  it("shows the registry seed and is what constructors default to", function()
    reg["outcrop.seed"] = 42
    assert.are.equal(42, oc.seed)
    local a = oc.turbulence{wavelength = 1}
    local b = oc.turbulence{wavelength = 1, seed = 42}
    local c = oc.turbulence{wavelength = 1, seed = 1}
    local differ = false
    for i = 1, 20 do
      local p = {0.37 * i, 0.21 * i, -0.13 * i}
      assert.are.equal(b:eval(p), a:eval(p))
      if c:eval(p) ~= a:eval(p) then differ = true end
    end
    assert.is_true(differ)
  end)

  it("applies to warp and perturb too", function()
    local p = oc.point{center = {0, 0, 0}, radius = 2}
    reg["outcrop.seed"] = 9
    local w = oc.warp(p, {wavelength = 0.5, amplitude = 0.3})
    local q = oc.perturb(p, {wavelength = 0.5, amplitude = 0.3})
    reg["outcrop.seed"] = saved
    local w9 = oc.warp(p, {wavelength = 0.5, amplitude = 0.3, seed = 9})
    local q9 = oc.perturb(p, {wavelength = 0.5, amplitude = 0.3, seed = 9})
    for i = 1, 20 do
      local x = {0.07 * i, 0.05 * i, 0.02 * i}
      assert.are.equal(w9:eval(x), w:eval(x))
      assert.are.equal(q9:eval(x), q:eval(x))
    end
  end)

  it("ignores a malformed registry value", function()
    reg["outcrop.seed"] = -5
    assert.are.equal(1, oc.seed)
    reg["outcrop.seed"] = "abc"
    assert.are.equal(1, oc.seed)
  end)
end)

describe("outcrop.version", function()
  it("is a version string", function()
    assert.matches("^%d+%.%d+%.%d+", oc.version)
  end)
end)

describe("the module", function()
  it("lets scripts add their own fields", function()
    oc.my_helper = 5
    assert.are.equal(5, oc.my_helper)
    oc.my_helper = nil
  end)
end)
