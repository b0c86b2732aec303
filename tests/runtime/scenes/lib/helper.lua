-- helper.lua: a pure Lua module for require.lua.
return {twice = function(x) return 2 * x end}
